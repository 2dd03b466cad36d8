#!/usr/bin/env python3
"""The cell-agent as it runs for months, against a real surfinspectd (and a
real mosquitto) on loopback, with small simulated parts (a 160 x 120 sensor):

- killed (SIGKILL) at random moments while parts are written: every folder
  in results/ is a whole set or absent, and the restarted agent completes
  each part once;
- a results folder on a small tmpfs that fills during a part: the part
  stays in the inbox, no partial set remains, disk_full is published
  (retained) and exported, the log says it once, and when space is freed
  the agent resumes and finishes every part;
- retention of N parts' heavy files: the newest sets stay whole, older ones
  lose their heavy files and keep their light files and database rows, and
  a part not yet delivered over MQTT is never pruned;
- a server that starts late: the agent logs "waiting for the server" once
  and goes on when it answers.

usage: agent_operations_test.py BIN_DIR [unittest args]
"""
import json
import os
import random
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import agent_soak_test as soak  # noqa: E402
from mqtt_e2e_test import Broker, Subscriber, free_port, retained_status  # noqa: E402

BIN = None
DEFAULT_FILES = {"report.json", "errormap.ply", "errormap.png", "report.pdf", "report.html", "result.qif"}
HEAVY = {"errormap.ply", "report.html"}


def part_folders(results):
    return sorted(e for e in os.listdir(results)
                  if not e.startswith(".") and os.path.isdir(os.path.join(results, e)))


def db_part_ids(db):
    with sqlite3.connect(db) as c:
        return sorted(r[0] for r in c.execute("SELECT part_id FROM parts"))


class OperationsTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="agent-ops-")
        # The soak's small calibrated cell (160 x 120 pixels, ~0.3 s a part)
        # and 8 parts made once, copied into each test's inbox.
        cell_json = soak.make_cell(cls.root)
        cls.template = os.path.dirname(cell_json)
        staged = soak.stage_parts(cls.root, cell_json, 8, seed=5)
        cls.parts = os.path.dirname(staged[0])
        cls.part_ids = [os.path.basename(p) for p in staged]
        cls.port = free_port()
        cls.server = soak.start_server(cls.port, os.path.join(cls.root, "server.log"))

    @classmethod
    def tearDownClass(cls):
        cls.server.kill()
        cls.server.wait()
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.dir = tempfile.mkdtemp(dir=self.root)
        shutil.copytree(self.template, os.path.join(self.dir, "cell"))
        self.stoppers = []

    def tearDown(self):
        for stop in reversed(self.stoppers):
            stop()

    def cell_json(self, **extra):
        path = os.path.join(self.dir, "cell", "cell.json")
        with open(path) as f:
            c = json.load(f)
        c.update(extra)
        with open(path, "w") as f:
            json.dump(c, f, indent=1)

    def drop(self, ids):
        for p in ids:
            shutil.copytree(os.path.join(self.parts, p), os.path.join(self.dir, "inbox", p))

    def agent(self, *extra, port=None, results="results", wait=True):
        cmd = [os.path.join(BIN, "cell-agent"), "run", "--cell", "cell/cell.json",
               "--server", f"127.0.0.1:{port or self.port}", "--inbox", "inbox", "--results", results,
               "--archive", "archive", "--quarantine", "quarantine", "--backoff", "0.2", "--backoff-max", "1",
               "--poll", "0.1", *extra]
        proc = subprocess.Popen(cmd, cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if not wait:
            self.stoppers.append(lambda: (proc.poll() is None and proc.kill(), proc.communicate()))
            return proc
        out, err = proc.communicate(timeout=300)
        return proc.returncode, out, err

    def assert_whole_sets(self, results, files=DEFAULT_FILES):
        for p in part_folders(results):
            self.assertEqual(set(os.listdir(os.path.join(results, p))) - {".mqtt-delivered"}, files, p)

    def read(self, name):
        with open(os.path.join(self.dir, name)) as f:
            return f.read()

    def wait_until(self, pred, timeout=120, what="condition"):
        deadline = time.time() + timeout
        while time.time() < deadline:
            if pred():
                return
            time.sleep(0.1)
        self.fail(f"no {what} within {timeout} s")

    def test_killed_at_random_moments_every_set_is_whole_and_each_part_done_once(self):
        self.drop(self.part_ids)
        for p in self.part_ids:  # each part twice, under a second id: 16 parts to kill through
            shutil.copytree(os.path.join(self.parts, p), os.path.join(self.dir, "inbox", p + "-b"))
        parts = sorted(self.part_ids + [p + "-b" for p in self.part_ids])
        results, inbox = os.path.join(self.dir, "results"), os.path.join(self.dir, "inbox")
        rng = random.Random(44)
        kills = mid_write = 0
        while kills < 20 and [p for p in os.listdir(inbox) if not p.startswith(".")]:
            proc = self.agent(wait=False)
            time.sleep(rng.uniform(0.25, 0.9))  # start-up takes ~0.3 s, a part ~0.3 s
            proc.send_signal(signal.SIGKILL)
            proc.communicate()
            kills += 1
            if os.path.exists(results):
                staging = os.path.join(results, ".partial")
                mid_write += bool(os.path.exists(staging) and os.listdir(staging))
                self.assert_whole_sets(results)  # before any restart cleans up
        code, out, err = self.agent("--once")
        self.assertEqual(code, 0, err)
        self.assertEqual(part_folders(results), parts)
        self.assert_whole_sets(results)
        self.assertEqual(sorted(os.listdir(os.path.join(self.dir, "archive"))), parts)
        self.assertFalse(os.path.exists(os.path.join(results, ".partial")))
        self.assertEqual(db_part_ids(os.path.join(results, "results.db")), parts)
        print(f"\n  {kills} kills, {mid_write} of them while a set was being written", file=sys.stderr)

    def test_a_full_disk_pauses_publishes_and_resumes(self):
        mnt = os.path.join(self.dir, "results")
        os.makedirs(mnt)
        if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=48m", "tmpfs", mnt],
                          capture_output=True).returncode != 0:
            self.skipTest("cannot mount a tmpfs here (needs root): the full-disk case is not checked")
        self.stoppers.append(lambda: subprocess.run(["umount", "-l", mnt]))
        self.cell_json(disk={"reserve_mb": 1})
        broker = Broker(self.dir).start()
        self.stoppers.append(broker.stop)
        sub = Subscriber(broker, os.path.join(self.dir, "sub.txt"))
        self.stoppers.append(sub.stop)
        self.drop(self.part_ids[:4])
        with open(os.path.join(mnt, "filler"), "wb") as f:  # room for about one part's set
            f.write(b"\0" * (44 << 20))
        proc = self.agent("--mqtt", f"tcp://127.0.0.1:{broker.port}", "--status-dir", self.dir, wait=False)
        self.wait_until(lambda: retained_status(broker) == "disk_full", what="disk_full status")
        self.assertIn('surfinspect_agent_disk_full{cell="cell"} 1', self.read("agent_status.prom"))
        self.assert_whole_sets(mnt)
        self.assertFalse(os.path.exists(os.path.join(mnt, ".partial")))
        inbox = sorted(os.listdir(os.path.join(self.dir, "inbox")))
        self.assertGreaterEqual(len(inbox), 3, "the parts wait in the inbox")
        time.sleep(2)  # several polls while full
        os.remove(os.path.join(mnt, "filler"))
        self.wait_until(lambda: len(part_folders(mnt)) == 4, what="all four parts")
        self.wait_until(lambda: retained_status(broker) == "online", what="online status again")
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
        self.assertEqual(err.count("parts wait in the inbox until space returns"), 1, err)
        self.assertEqual(err.count("disk space is back"), 1, err)
        self.assert_whole_sets(mnt)
        self.assertEqual(sorted(os.listdir(os.path.join(self.dir, "archive"))), self.part_ids[:4])
        self.assertIn('surfinspect_agent_disk_full{cell="cell"} 0', self.read("agent_status.prom"))
        states = [m["state"] for t, m in sub.messages() if t.endswith("/status")]
        self.assertIn("disk_full", states)

    def test_retention_keeps_the_newest_sets_whole_and_never_prunes_undelivered_parts(self):
        self.cell_json(retention={"heavy": {"parts": 2}})
        self.drop(self.part_ids[:5])
        results = os.path.join(self.dir, "results")
        # A broker that is not there: nothing is delivered, so nothing is pruned.
        code, out, err = self.agent("--once", "--mqtt", f"tcp://127.0.0.1:{free_port()}")
        self.assertEqual(code, 0, err)
        self.assert_whole_sets(results)
        self.assertIn("due but kept", err)
        # Without MQTT the database alone settles a part: prune on demand.
        p = subprocess.run([os.path.join(BIN, "cell-agent"), "prune", "--cell", "cell/cell.json",
                            "--results", "results", "--inbox", "inbox"], cwd=self.dir,
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("pruned 3 parts' heavy files", p.stdout)
        newest = self.part_ids[3:5]  # inspected in name order, so the last two are the newest
        for part in self.part_ids[:5]:
            files = set(os.listdir(os.path.join(results, part))) - {".mqtt-delivered"}
            expected = DEFAULT_FILES if part in newest else DEFAULT_FILES - HEAVY
            self.assertEqual(files, expected, part)
        self.assertEqual(db_part_ids(os.path.join(results, "results.db")), self.part_ids[:5])

    def test_a_server_that_starts_late_is_waited_for_and_then_used(self):
        port = free_port()
        self.drop(self.part_ids[:1])
        proc = self.agent("--once", port=port, wait=False)
        time.sleep(3)
        server = soak.start_server(port, os.path.join(self.dir, "server.log"))
        self.stoppers.append(lambda: (server.kill(), server.wait()))
        out, err = proc.communicate(timeout=120)
        self.assertEqual(proc.returncode, 0, err)
        self.assertEqual(err.count("waiting for the server (cannot reach surfinspectd at"), 1, err)
        self.assertIn(f"surfinspectd at 127.0.0.1:{port} answers; going on", err)
        self.assertEqual(part_folders(os.path.join(self.dir, "results")), self.part_ids[:1])


if __name__ == "__main__":
    BIN = soak.BIN = sys.argv.pop(1)
    unittest.main(verbosity=2)
