#!/usr/bin/env python3
"""Scale-out on one machine: three surfinspectd replicas on
loopback ports, one cell-agent with round_robin over all three, six parts,
and the replica that is computing a part is killed mid-run. Every part must
end with results exactly once, and the replicas' own Prometheus counters
must show that the load reached more than one of them. Then the compose
layout: two replicas must share three parts. Standard library only.

usage: scale_out_test.py BIN_DIR [unittest args]
"""
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest
import urllib.request

BIN = None
PARTS = 6


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Replica:
    """One surfinspectd with a /metrics port; remembers its last scrape, so
    a killed replica's counters are not lost with it."""

    def __init__(self):
        self.port, self.metrics_port = free_port(), free_port()
        self.proc = subprocess.Popen(
            [os.path.join(BIN, "surfinspectd"), "--listen", f"127.0.0.1:{self.port}",
             "--metrics-listen", f"127.0.0.1:{self.metrics_port}", "--threads", "1",
             "--max-connection-age", "0"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        self.proc.stdout.close()
        assert "listening on" in line, f"server did not start: {line!r}"
        self.last = {}

    def scrape(self):
        """{(name, labels): value} from /metrics, or the last scrape if dead."""
        if self.proc.poll() is not None:
            return self.last
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{self.metrics_port}/metrics", timeout=2) as r:
                text = r.read().decode()
        except OSError:
            return self.last
        values = {}
        for line in text.splitlines():
            m = re.match(r"^(\w+)(\{[^}]*\})?\s+(\S+)$", line)
            if m:
                values[(m.group(1), m.group(2) or "")] = float(m.group(3))
        self.last = values
        return values

    def inspect_ok(self):
        return self.scrape().get(("surfinspect_rpcs_total", '{code="OK",method="Inspect"}'), 0)

    def inspect_mesh_misses(self):
        # Inspect's codes are labelled by number (9), the unary ones by name.
        m = self.scrape()
        return sum(m.get(("surfinspect_rpcs_total", f'{{code="{c}",method="Inspect"}}'), 0)
                   for c in ("9", "FAILED_PRECONDITION"))

    def in_flight(self):
        return self.scrape().get(("surfinspect_calls_in_flight", ""), 0)

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


class ScaleOutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # The demo cell with six production parts, calibrated once.
        cls.root = tempfile.mkdtemp(prefix="scale-out-")
        subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", "cell", "--parts", str(PARTS)],
                       cwd=cls.root, check=True, stdout=subprocess.DEVNULL)
        server = Replica()
        try:
            out = subprocess.run([os.path.join(BIN, "cell-agent"), "calibrate", "--cell", "cell/cell.json",
                                  "--server", f"127.0.0.1:{server.port}"],
                                 cwd=cls.root, check=True, capture_output=True, text=True).stdout
        finally:
            server.kill()
        assert "calibrated 5 of 5" in out, out

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.dir = tempfile.mkdtemp(dir=self.root)
        shutil.copytree(os.path.join(self.root, "cell"), os.path.join(self.dir, "cell"))
        self.replicas = []
        self.agent_proc = None

    def tearDown(self):
        if self.agent_proc and self.agent_proc.poll() is None:
            self.agent_proc.kill()
            self.agent_proc.communicate()
        for r in self.replicas:
            r.kill()

    def drop_parts(self, n):
        """The scanner's side of the inbox protocol: scans, then DONE."""
        parts = sorted(os.listdir(os.path.join(self.dir, "cell", "scans")))[:n]
        self.assertEqual(len(parts), n)
        for p in parts:
            dst = os.path.join(self.dir, "inbox", p)
            shutil.copytree(os.path.join(self.dir, "cell", "scans", p), dst)
            open(os.path.join(dst, "DONE"), "w").close()
        return parts

    def start_agent(self, target, *extra):
        self.agent_proc = subprocess.Popen(
            [os.path.join(BIN, "cell-agent"), "run", "--cell", "cell/cell.json", "--server", target,
             "--inbox", "inbox", "--results", "results", "--archive", "archive",
             "--quarantine", "quarantine", "--backoff", "0.2", "--backoff-max", "1", "--timeout", "60", *extra],
            cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def archived(self):
        archive = os.path.join(self.dir, "archive")
        return len(os.listdir(archive)) if os.path.isdir(archive) else 0

    def assert_exactly_once(self, parts, out, err):
        results = os.path.join(self.dir, "results")  # part folders; results.db is the store
        self.assertEqual(sorted(d for d in os.listdir(results) if os.path.isdir(os.path.join(results, d))), parts, err)
        for p in parts:
            for f in ("report.json", "errormap.ply", "errormap.png", "report.pdf", "report.html", "result.qif"):
                self.assertTrue(os.path.exists(os.path.join(self.dir, "results", p, f)), f"{p}/{f}")
            # The CSV is the largest file by far: off unless cell.json's "outputs" names it.
            self.assertFalse(os.path.exists(os.path.join(self.dir, "results", p, "deviations.csv")), p)
        self.assertEqual(sorted(os.listdir(os.path.join(self.dir, "archive"))), parts)
        self.assertEqual([d for d in os.listdir(os.path.join(self.dir, "inbox")) if not d.startswith(".")], [])
        quarantine = os.path.join(self.dir, "quarantine")
        self.assertFalse(os.path.isdir(quarantine) and os.listdir(quarantine), "a part was quarantined")
        for p in parts:
            self.assertEqual(sum(1 for line in out.splitlines() if line.startswith(p + " ")), 1,
                             f"{p} reported other than once:\n{out}")

    def test_three_replicas_round_robin_one_killed_mid_part(self):
        parts = self.drop_parts(PARTS)
        self.replicas = [Replica() for _ in range(3)]
        self.assertEqual([r.inspect_ok() for r in self.replicas], [0, 0, 0])
        self.start_agent("ipv4:" + ",".join(f"127.0.0.1:{r.port}" for r in self.replicas))

        # Once a part is done, kill the replica that is computing the next
        # one: the agent's call fails with UNAVAILABLE and is retried on the
        # other two.
        victim = None
        deadline = time.time() + 120
        while victim is None and time.time() < deadline and self.agent_proc.poll() is None:
            if self.archived() >= 1:
                busy = [r for r in self.replicas if r.in_flight() >= 1]
                if busy:
                    victim = busy[0]
                    victim.kill()
            time.sleep(0.05)
        self.assertIsNotNone(victim, "never saw a replica with an Inspect in flight after the first part")
        archived_at_kill = self.archived()
        self.assertLess(archived_at_kill, PARTS, "the kill came after the run, not during it")

        deadline = time.time() + 180
        while self.archived() < PARTS and time.time() < deadline and self.agent_proc.poll() is None:
            time.sleep(0.2)
        self.agent_proc.send_signal(signal.SIGTERM)
        out, err = self.agent_proc.communicate(timeout=60)
        self.assert_exactly_once(parts, out, err)

        # The load reached more than one replica, in their own metrics (the
        # killed one's last scrape before the kill).
        served = [r.inspect_ok() for r in self.replicas]
        print(f"\nInspect OK per replica {served} (replica {self.replicas.index(victim)} killed "
              f"after {archived_at_kill} parts)", file=sys.stderr)
        self.assertGreaterEqual(sum(1 for s in served if s > 0), 2, served)
        survivors = [r for r in self.replicas if r is not victim]
        self.assertTrue(all(r.proc.poll() is None for r in survivors))
        self.assertEqual([r.inspect_mesh_misses() for r in self.replicas], [0, 0, 0])
        # Every part was computed once, except that the victim may have
        # finished one call between its last scrape and the kill.
        self.assertIn(sum(served), (PARTS - 1, PARTS), served)

    def test_two_replicas_share_the_parts(self):
        # The compose layout. Each part is one Inspect call, so round_robin
        # alternates the replicas; no replica may be left answering
        # MESH_NOT_CACHED while the other does the work.
        # Three parts: the first call may go out while only one replica is
        # connected; from then on round_robin alternates.
        parts = self.drop_parts(3)
        self.replicas = [Replica() for _ in range(2)]
        self.start_agent("ipv4:" + ",".join(f"127.0.0.1:{r.port}" for r in self.replicas), "--once")
        out, err = self.agent_proc.communicate(timeout=300)
        self.assertEqual(self.agent_proc.returncode, 0, err)
        self.assert_exactly_once(parts, out, err)
        served = [r.inspect_ok() for r in self.replicas]
        print(f"\nInspect OK per replica {served}", file=sys.stderr)
        self.assertEqual(sum(served), 3)
        self.assertTrue(all(s >= 1 for s in served), served)
        self.assertEqual([r.inspect_mesh_misses() for r in self.replicas], [0, 0])


if __name__ == "__main__":
    BIN = os.path.abspath(sys.argv[1])
    unittest.main(argv=[sys.argv[0]] + sys.argv[2:], verbosity=2)
