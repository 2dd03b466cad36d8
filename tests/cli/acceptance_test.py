#!/usr/bin/env python3
"""`surfinspect acceptance` and `cell-agent verify` as a user runs them, on the
demo cell calibrated through a real surfinspectd on loopback: the report's
figures with their uncertainties and verdicts, the same report through
--server, and clear errors for bad input (negative diameter, a sphere not in
its scan, a plate with too few points, an uncalibrated cell, verify without a
stored calibration); a drifted robot fails verify. Standard library only.

usage: acceptance_test.py BIN_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

BIN = None


def load(path):
    with open(path) as f:
        return json.load(f)


def run(*args, cwd=None):
    return subprocess.run([os.path.join(BIN, args[0]), *args[1:]], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


class AcceptanceCli(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="acceptance_test_")
        cls.cell = os.path.join(cls.root, "cell")
        r = run("surfinspect", "demo-cell", "--out", cls.cell, "--parts", "0")
        assert r.returncode == 0, r.stderr
        shutil.copytree(cls.cell, os.path.join(cls.root, "uncalibrated"))
        cls.server = subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen", "127.0.0.1:0",
                                       "--threads", "1"], stdout=subprocess.PIPE,
                                      stderr=subprocess.DEVNULL, text=True)
        line = cls.server.stdout.readline()
        cls.server.stdout.close()
        assert "listening on" in line, line
        cls.target = line.split("listening on")[1].strip()
        r = run("cell-agent", "calibrate", "--cell", os.path.join(cls.cell, "cell.json"), "--server",
                cls.target)
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        cls.server.terminate()
        cls.server.wait(timeout=30)
        shutil.rmtree(cls.root, ignore_errors=True)

    def accept(self, artefacts=None, cell=None, extra=()):
        acc = os.path.join(self.cell, "acceptance")
        report = os.path.join(self.root, "R.json")
        if os.path.exists(report):
            os.remove(report)
        r = run("surfinspect", "acceptance", "--cell", os.path.join(cell or self.cell, "cell.json"),
                "--scans", os.path.join(acc, "scans"), "--artefacts",
                artefacts or os.path.join(acc, "artefacts.json"), "--report", report, *extra)
        return r, (load(report) if os.path.exists(report) else None)

    def edited(self, edit):
        a = load(os.path.join(self.cell, "acceptance", "artefacts.json"))
        edit(a)
        path = os.path.join(self.root, "edited.json")
        with open(path, "w") as f:
            json.dump(a, f)
        return path

    def test_report_has_every_figure_with_uncertainty_and_truth_is_recovered(self):
        r, rep = self.accept()
        self.assertEqual(r.returncode, 0, r.stderr)
        truth = load(os.path.join(self.cell, "acceptance", "artefacts.json"))["simulation_truth"]
        for key in ("PF_mm", "PS_mm", "F_mm"):
            for field in ("value", "u", "U", "mpe", "pass"):
                self.assertIn(field, rep[key])
        self.assertEqual(len(rep["SD_mm"]), 8)
        self.assertEqual(sum(s["cross_view"] for s in rep["SD_mm"]), 4)
        for s in rep["SD_mm"]:
            self.assertLessEqual(abs(s["value"] - truth["SD_mm"]), 3 * s["u"] + 1e-4, s)
        self.assertLessEqual(abs(rep["PS_mm"]["value"] - truth["PS_mm"]), 2 * rep["PS_mm"]["U"])
        self.assertEqual(rep["verdict"], "pass")
        self.assertIn("verdict: pass", r.stdout)

    def test_server_filters_and_registers_to_the_same_report(self):
        r, local = self.accept()
        r2, remote = self.accept(extra=("--server", self.target))
        self.assertEqual(r2.returncode, 0, r2.stderr)
        self.assertEqual(local, remote)

    def test_negative_diameter_is_a_clear_error(self):
        path = self.edited(lambda a: a["sphere"].update(diameter_mm=-25.0))
        r, rep = self.accept(path)
        self.assertEqual(r.returncode, 1)
        self.assertIn("sphere.diameter_mm: must be > 0", r.stderr)
        self.assertIsNone(rep)

    def test_sphere_not_in_scan_is_a_clear_error(self):
        def move(a):
            a["sphere"]["measurements"][0]["centre_mm"][1] += 150
        r, rep = self.accept(self.edited(move))
        self.assertEqual(r.returncode, 1)
        self.assertIn("sphere-1", r.stderr)
        self.assertIn("not in the scan", r.stderr)
        self.assertIsNone(rep)

    def test_plate_with_too_few_points_is_a_clear_error(self):
        def shrink(a):
            a["plate"]["measurements"][0]["radius_mm"] = 0.5
        r, rep = self.accept(self.edited(shrink))
        self.assertEqual(r.returncode, 1)
        self.assertIn("plate-1", r.stderr)
        self.assertIn("at least 200 needed", r.stderr)

    def test_uncalibrated_cell_is_a_clear_error(self):
        r, rep = self.accept(cell=os.path.join(self.root, "uncalibrated"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("is not a calibrated viewpoint", r.stderr)

    def test_verify_without_calibration_errs_and_drift_fails(self):
        r = run("cell-agent", "verify", "--cell", os.path.join(self.root, "uncalibrated", "cell.json"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("has no stored calibration; run cell-agent calibrate first", r.stderr)
        status = os.path.join(self.root, "status")
        r = run("cell-agent", "verify", "--cell", os.path.join(self.cell, "cell.json"),
                "--robot-drift", "v2:0.02", "--status-dir", status)
        self.assertEqual(r.returncode, 3, r.stdout + r.stderr)
        self.assertIn("calibration fail: v2", r.stdout)
        state = load(os.path.join(status, "calibration_status.json"))
        self.assertEqual(state["state"], "fail")
        self.assertEqual([v["state"] for v in state["viewpoints"]], ["ok", "fail", "ok", "ok", "ok"])
        r = run("cell-agent", "verify", "--cell", os.path.join(self.cell, "cell.json"),
                "--status-dir", status)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_recalibration_keeps_the_previous_one(self):
        work = os.path.join(self.root, "recal")
        shutil.copytree(self.cell, work)
        r = run("cell-agent", "calibrate", "--cell", os.path.join(work, "cell.json"), "--server",
                self.target)
        self.assertEqual(r.returncode, 0, r.stderr)
        kept = [f for f in os.listdir(work) if f.startswith("cell.calibration-")]
        self.assertEqual(len(kept), 1)
        old = load(os.path.join(work, kept[0]))
        self.assertIn("world_from_sensor", old["viewpoints"][0])


if __name__ == "__main__":
    BIN = sys.argv.pop(1)
    unittest.main()
