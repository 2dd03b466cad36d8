#!/usr/bin/env python3
"""End-to-end and fault tests of cell-agent against real surfinspectd
processes on loopback: verdicts and dent depths against the
simulated truth, server killed mid-part, agent killed mid-part, a corrupt
scan quarantined, two replicas with one killed. Standard library only.

usage: agent_e2e_test.py BIN_DIR [unittest args]
"""
import json
import math
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import unittest

BIN = None


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    """surfinspectd on a fixed loopback port (so it can be restarted there)."""

    def __init__(self, port, log):
        self.port = port
        self.log = log
        self.proc = None

    def start(self):
        self.proc = subprocess.Popen(
            [os.path.join(BIN, "surfinspectd"), "--listen", f"127.0.0.1:{self.port}",
             "--threads", "1", "--max-connection-age", "0"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        self.proc.stdout.close()
        assert "listening on" in line, f"server did not start: {line!r}"
        return self

    def kill(self):
        if self.proc and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            self.proc.wait(timeout=30)


def read_ply(path):
    """(x, y, z, deviation) per point from the binary error-map PLY."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    n = int([l for l in header.splitlines() if l.startswith("element vertex")][0].split()[2])
    rec = struct.Struct("<5f3B")  # x y z scalar_deviation quality red green blue
    return [rec.unpack_from(data, end + i * rec.size)[:4] for i in range(n)]


def load_json(path):
    with open(path) as f:
        return json.load(f)


def matrix(m):
    return m["matrix"]


def apply(m, p):
    return [sum(m[r][c] * p[c] for c in range(3)) + m[r][3] for r in range(3)]


class AgentTests(unittest.TestCase):
    cell_template = None

    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="agent-e2e-")
        # One calibrated cell, shared: the gauge scans and ICP run once.
        cell = os.path.join(cls.root, "template")
        subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", cell, "--parts", "0"],
                       check=True, stdout=subprocess.DEVNULL)
        server = Server(free_port(), os.path.join(cls.root, "calibrate.log")).start()
        try:
            out = subprocess.run([os.path.join(BIN, "cell-agent"), "calibrate", "--cell",
                                  os.path.join(cell, "cell.json"), "--server", f"127.0.0.1:{server.port}"],
                                 check=True, capture_output=True, text=True).stdout
        finally:
            server.stop()
        assert "calibrated 5 of 5" in out, out
        cls.cell_template = cell

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.dir = tempfile.mkdtemp(dir=self.root)
        shutil.copytree(self.cell_template, os.path.join(self.dir, "cell"))
        self.servers = []

    def tearDown(self):
        for s in self.servers:
            s.kill()

    def server(self, port=None):
        s = Server(port or free_port(), os.path.join(self.dir, "server.log")).start()
        self.servers.append(s)
        return s

    def agent(self, target, *extra, wait=True):
        cmd = [os.path.join(BIN, "cell-agent"), "run", "--cell", "cell/cell.json", "--server", target,
               "--inbox", "inbox", "--results", "results", "--archive", "archive",
               "--quarantine", "quarantine", "--backoff", "0.2", "--backoff-max", "1", "--timeout", "60",
               *extra]
        proc = subprocess.Popen(cmd, cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if not wait:
            return proc
        out, err = proc.communicate(timeout=400)
        return proc.returncode, out, err

    def drop_parts(self, n, seed):
        """Puts n simulated parts into the inbox without processing them."""
        tmp = tempfile.mkdtemp(dir=self.dir)
        code = subprocess.run(
            [os.path.join(BIN, "cell-agent"), "run", "--cell", os.path.join(self.dir, "cell", "cell.json"),
             "--server", "127.0.0.1:1", "--inbox", os.path.join(self.dir, "inbox"),
             "--results", os.path.join(tmp, "r"), "--simulate", str(n), "--seed", str(seed),
             "--once", "--max-attempts", "1", "--timeout", "1"],
            capture_output=True, text=True)
        # The throwaway run could not reach a server, so every part is still
        # in the inbox (retryable errors never quarantine).
        parts = sorted(os.listdir(os.path.join(self.dir, "inbox")))
        self.assertEqual(len(parts), n, code.stderr)
        return parts

    def wait_for_archive(self, n, timeout=300):
        archive = os.path.join(self.dir, "archive")
        deadline = time.time() + timeout
        while time.time() < deadline and (len(os.listdir(archive)) if os.path.exists(archive) else 0) < n:
            time.sleep(0.2)

    def assert_exactly_once(self, parts):
        root = os.path.join(self.dir, "results")  # part folders; results.db is the store
        results = sorted(d for d in os.listdir(root) if os.path.isdir(os.path.join(root, d)))
        self.assertEqual(results, sorted(parts))
        for p in parts:
            for f in ("report.json", "errormap.ply", "errormap.png", "report.pdf", "report.html", "result.qif"):
                self.assertTrue(os.path.exists(os.path.join(self.dir, "results", p, f)), f"{p}/{f}")
            # The CSV is the largest file by far: off unless cell.json's "outputs" names it.
            self.assertFalse(os.path.exists(os.path.join(self.dir, "results", p, "deviations.csv")), p)
        self.assertEqual(sorted(os.listdir(os.path.join(self.dir, "archive"))), sorted(parts))
        self.assertEqual([d for d in os.listdir(os.path.join(self.dir, "inbox")) if not d.startswith(".")], [])

    def test_verdicts_and_dent_depths_match_the_truth(self):
        parts = self.drop_parts(3, seed=11)
        server = self.server()
        code, out, err = self.agent(f"127.0.0.1:{server.port}", "--once")
        self.assertEqual(code, 0, err)
        self.assert_exactly_once(parts)
        cell = load_json(os.path.join(self.dir, "cell", "cell.json"))
        world_from_part = matrix(cell["part"]["world_from_part"])
        tol = cell["tolerance_mm"]
        for p in parts:
            truth = load_json(os.path.join(self.dir, "archive", p, "truth.json"))["defects"]
            report = load_json(os.path.join(self.dir, "results", p, "report.json"))
            points = read_ply(os.path.join(self.dir, "results", p, "errormap.ply"))
            for d in truth:
                c = apply(world_from_part, d["center_in_part"])
                sigma = d["radius_mm"] / 2
                # Least-squares amplitude of the known Gaussian profile over
                # the points near the centre: the measured depth.
                num = den = 0.0
                for x, y, z, dev in points:
                    r2 = (x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2
                    if r2 < sigma * sigma and not math.isnan(dev):
                        g = math.exp(-r2 / (2 * sigma * sigma))
                        num += dev * g
                        den += g * g
                self.assertGreater(den, 10, f"{p}: no points on the defect")
                measured_depth = -num / den
                self.assertLess(abs(measured_depth - d["depth_mm"]), 0.020,
                                f"{p}: planted {d['depth_mm']:.4f} mm, measured {measured_depth:.4f} mm")
            # The verdict follows the planted defects: a part fails when a
            # defect is deeper than the tolerance over an area larger than
            # the allowed fraction (small dents pass).
            deepest = max(abs(d["depth_mm"]) for d in truth)
            if deepest < 0.8 * tol:
                self.assertEqual(report["tolerance"]["verdict"], "pass", p)
            self.assertIn(p, out)

    def test_server_killed_mid_part_then_restarted(self):
        parts = self.drop_parts(3, seed=12)
        server = self.server()
        agent = self.agent(f"127.0.0.1:{server.port}", wait=False)
        # Kill the server while the first part is being computed (a part
        # takes ~2 s of server time), bring it back on the same port.
        time.sleep(1.5)
        server.kill()
        time.sleep(1.5)
        self.server(server.port)
        self.wait_for_archive(3)
        agent.send_signal(signal.SIGTERM)
        agent.communicate(timeout=60)
        self.assert_exactly_once(parts)

    def test_agent_killed_mid_part_then_restarted(self):
        parts = self.drop_parts(3, seed=13)
        server = self.server()
        agent = self.agent(f"127.0.0.1:{server.port}", wait=False)
        time.sleep(2.5)  # mid-way through the first or second part
        agent.kill()
        agent.wait()
        code, out, err = self.agent(f"127.0.0.1:{server.port}", "--once")
        self.assertEqual(code, 0, err)
        self.assert_exactly_once(parts)

    def test_corrupt_scan_is_quarantined_and_the_queue_goes_on(self):
        parts = self.drop_parts(3, seed=14)
        bad, crafted = parts[0], parts[2]
        scan = os.path.join(self.dir, "inbox", bad, "v2.pcd")
        with open(scan, "r+b") as f:
            f.truncate(os.path.getsize(scan) // 2)
        # A header shape that used to crash the reader: a first line that is
        # no keyword, a garbage COUNT and a second header after the first.
        with open(os.path.join(self.dir, "inbox", crafted, "v1.pcd"), "wb") as f:
            f.write(b"hello\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT a b c\nWIDTH 1\n"
                    b"HEIGHT 1\nPOINTS 1\nDATA binary\n" + b"\0" * 12 +
                    b"VERSION 0.7\nFIELDS x\nDATA ascii\n")
        server = self.server()
        code, out, err = self.agent(f"127.0.0.1:{server.port}", "--once")
        self.assertEqual(code, 3, err)  # 3 = something was quarantined; the agent did not crash
        with open(os.path.join(self.dir, "quarantine", bad, "error.txt")) as f:
            why = f.read()
        self.assertIn("truncated", why)
        with open(os.path.join(self.dir, "quarantine", crafted, "error.txt")) as f:
            self.assertIn("v1.pcd", f.read())
        self.assertTrue(os.path.exists(os.path.join(self.dir, "results", parts[1], "report.json")))
        self.assertFalse(os.path.exists(os.path.join(self.dir, "results", bad)))
        self.assertFalse(os.path.exists(os.path.join(self.dir, "inbox", crafted)))

    def test_two_replicas_round_robin_one_killed(self):
        parts = self.drop_parts(3, seed=15)
        a, b = self.server(), self.server()
        agent = self.agent(f"ipv4:127.0.0.1:{a.port},127.0.0.1:{b.port}", wait=False)
        time.sleep(2.0)
        b.kill()
        self.wait_for_archive(3)
        agent.send_signal(signal.SIGTERM)
        agent.communicate(timeout=60)
        self.assert_exactly_once(parts)


if __name__ == "__main__":
    BIN = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0]] + sys.argv[2:], verbosity=2)
