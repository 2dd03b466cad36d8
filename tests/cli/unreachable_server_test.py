#!/usr/bin/env python3
"""The CLI against a server that is not there, and a part's files as one
whole set: errormap, inspect and filter with --server at a closed loopback
port fail within 5 s naming the address and the refusal; --wait-for-server
waits for a server that starts late; inspect takes the part id from a
scans folder given with a trailing slash; an inspect whose writing fails
(a full tmpfs, skipped loudly where it cannot be mounted) leaves no file.

usage: unreachable_server_test.py BIN_DIR [unittest args]
"""
import json
import os
import shutil
import socket
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


def cli(*args, **kw):
    t0 = time.time()
    p = subprocess.run([os.path.join(BIN, "surfinspect"), *args], capture_output=True, text=True, **kw)
    return p, time.time() - t0


class CliTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="cli-unreachable-")
        cls.cell = os.path.join(cls.root, "cell")
        subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", cls.cell, "--parts", "1"],
                       check=True, stdout=subprocess.DEVNULL)
        cls.scans = os.path.join(cls.cell, "scans", sorted(os.listdir(os.path.join(cls.cell, "scans")))[0])
        # Calibration is not under test: the simulation's true poses stand in for it.
        path = os.path.join(cls.cell, "cell.json")
        with open(path) as f:
            cell = json.load(f)
        for vp in cell["viewpoints"]:
            vp["world_from_sensor"] = vp["simulation_truth_world_from_sensor"]
        with open(path, "w") as f:
            json.dump(cell, f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def out(self, name):
        return os.path.join(self.root, name)

    def test_each_command_fails_fast_naming_the_address_and_the_refusal(self):
        target = f"127.0.0.1:{free_port()}"  # nothing listens there
        pcd = os.path.join(self.scans, "v1.pcd")
        commands = {
            "errormap": ["errormap", "--cloud", pcd, "--mesh", os.path.join(self.cell, "part.stl"),
                         "--out", self.out("e.ply")],
            "inspect": ["inspect", "--cell", os.path.join(self.cell, "cell.json"), "--scans", self.scans,
                        "--out", self.out("inspect-refused")],
            "filter": ["filter", "--in", pcd, "--out", self.out("f.pcd")],
        }
        for name, args in commands.items():
            with self.subTest(command=name):
                p, seconds = cli(*args, "--server", target, timeout=60)
                self.assertNotEqual(p.returncode, 0)
                self.assertLess(seconds, 5.0, f"{name} took {seconds:.1f} s")
                self.assertIn(f"cannot reach surfinspectd at {target}", p.stderr)
                self.assertIn("refused", p.stderr.lower(), p.stderr)
        self.assertFalse(os.path.exists(self.out("inspect-refused")))

    def test_wait_for_server_waits_for_one_that_starts_late(self):
        port = free_port()
        server = None

        def start_later():
            time.sleep(2)
            return subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen", f"127.0.0.1:{port}",
                                     "--threads", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        client = subprocess.Popen([os.path.join(BIN, "surfinspect"), "health", "--server", f"127.0.0.1:{port}",
                                   "--wait-for-server", "30"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True)
        try:
            server = start_later()
            out, err = client.communicate(timeout=60)
            self.assertEqual(client.returncode, 0, err)
            self.assertIn("SERVING", out)
            self.assertIn(f"waiting up to 30 s for surfinspectd at 127.0.0.1:{port}", err)
        finally:
            client.kill()
            if server:
                server.kill()
                server.wait()

    def test_a_trailing_slash_names_the_part_by_its_folder(self):
        out = self.out("slash")
        p, _ = cli("inspect", "--cell", os.path.join(self.cell, "cell.json"), "--scans", self.scans + "/",
                   "--out", out, "--outputs", "png")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertTrue(p.stdout.startswith(os.path.basename(self.scans) + ":"), p.stdout)
        self.assertEqual(sorted(os.listdir(out)), ["errormap.png", "report.json"])

    def test_an_inspect_that_cannot_finish_writing_leaves_no_file(self):
        mnt = tempfile.mkdtemp(dir=self.root)
        if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=8m", "tmpfs", mnt],
                          capture_output=True).returncode != 0:
            self.skipTest("cannot mount a tmpfs here (needs root): the full-disk case is not checked")
        try:
            out = os.path.join(mnt, "part")
            # The PLY of 2 M points (~47 MB), written first, cannot fit in 8 MB.
            p, _ = cli("inspect", "--cell", os.path.join(self.cell, "cell.json"), "--scans", self.scans,
                       "--out", out, "--outputs", "png,ply,pdf")
            self.assertNotEqual(p.returncode, 0)
            self.assertIn("no space left on the file system of", p.stderr)
            self.assertEqual(os.listdir(mnt), [], "not even a staging folder")
        finally:
            subprocess.run(["umount", "-l", mnt])


if __name__ == "__main__":
    BIN = sys.argv.pop(1)
    unittest.main(verbosity=2)
