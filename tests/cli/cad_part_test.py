#!/usr/bin/env python3
"""STEP parts from the command line to the cell-agent, with the real files in
../shared/realdata/cad (skipped loudly where they are absent):

- `surfinspect cad` writes an OBJ whose g lines carry face:N, color: and
  body: groups, and a report whose measured error is within the tolerance;
  a tolerance below the file's own B-rep tolerance exits 1 and says why;
- `surfinspect errormap --mesh PART.stp` reports cad.tessellation_error_mm,
  and a plan region {"group": "face:N"} holds the points of that face only;
- a cell whose part is the NIST STEP file runs through `inspect` (the first
  tessellates, the second reuses the cache and says so) and through the
  cell-agent against a real surfinspectd (the log says the cache was reused,
  report.json carries "cad");
- an agent whose STEP part is truncated, or whose CAD worker hangs past the
  cell's timeout_s, quarantines every part with the reason and keeps running.

usage: cad_part_test.py BIN_DIR [unittest args]
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "client", "agent"))
import agent_soak_test as soak  # noqa: E402

BIN = None
REAL = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                     "..", "..", "..", "shared", "realdata", "cad"))
NIST = os.path.join(REAL, "nist_ctc_01_asme1_ap242-e1.stp")
BRACKET = os.path.join(REAL, "bug3883_xr2-ct-214_l-bracket.stp")
IDENTITY = {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}
# The bracket 400 mm in front of a sensor at the world origin, seen from +z.
BRACKET_POSE = {"matrix": [[1, 0, 0, -25], [0, -1, 0, 30], [0, 0, -1, 400], [0, 0, 0, 1]]}
# NIST's top (z = 50 in its file) near the demo pillar's top, under the demo viewpoints.
NIST_POSE = {"matrix": [[1, 0, 0, 600], [0, 1, 0, 100], [0, 0, 1, 15], [0, 0, 0, 1]]}


def cli(*args, check=True):
    r = subprocess.run([os.path.join(BIN, "surfinspect"), *args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"surfinspect {' '.join(args)}: exit {r.returncode}\n{r.stderr}")
    return r


def write_json(path, value):
    with open(path, "w") as f:
        json.dump(value, f, indent=1)
    return path


def load_json(path):
    with open(path) as f:
        return json.load(f)


def obj_faces(path):
    """{group: [(vertex, vertex, vertex)]} and the vertices of an OBJ with g lines."""
    vertices, groups, names = [], {}, []
    with open(path) as f:
        for line in f:
            tok = line.split()
            if not tok:
                continue
            if tok[0] == "v":
                vertices.append(tuple(float(t) for t in tok[1:4]))
            elif tok[0] == "g":
                names = tok[1:]
            elif tok[0] == "f":
                tri = tuple(vertices[int(t.split("/")[0]) - 1] for t in tok[1:4])
                for n in names:
                    groups.setdefault(n, []).append(tri)
    return groups


def largest_face_facing(groups, axis, sign):
    """The face:N group with the largest area whose normal points along sign * axis."""
    def area_facing(tris):
        total = 0.0
        for a, b, c in tris:
            u = [b[k] - a[k] for k in range(3)]
            v = [c[k] - a[k] for k in range(3)]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            total += max(0.0, sign * n[axis]) / 2
        return total
    faces = {g: t for g, t in groups.items() if g.startswith("face:")}
    return max(faces, key=lambda g: area_facing(faces[g]))


@unittest.skipUnless(os.path.isdir(REAL), f"SKIPPED: real CAD files absent ({REAL})")
class CadCommandTests(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="cad-cli-")

    def path(self, name):
        return os.path.join(self.dir, name)

    def test_cad_writes_groups_and_the_measured_error(self):
        r = cli("cad", "--in", BRACKET, "--out", self.path("b.obj"), "--chord-tolerance", "0.01")
        self.assertIn("tessellated (STEP, declared unit MILLIMETRE, 16 faces", r.stdout)
        report = load_json(self.path("b.cad.json"))
        self.assertTrue(report["tolerance_held"])
        self.assertLessEqual(report["tessellation_error_mm"], 0.01)
        self.assertEqual(report["faces"], 16)
        self.assertEqual(len(report["face_error_mm"]), 16)
        groups = obj_faces(self.path("b.obj"))
        self.assertEqual(sorted(g for g in groups if g.startswith("face:")),
                         sorted(f"face:{i}" for i in range(1, 17)))
        self.assertEqual(len(groups["body:l-bracket"]), report["triangles"])
        self.assertEqual(sum(len(t) for g, t in groups.items() if g.startswith("face:")),
                         report["triangles"])

    def test_a_tolerance_below_the_files_own_is_refused_with_the_reason(self):
        r = cli("cad", "--in", NIST, "--out", self.path("n.obj"), "--chord-tolerance", "0.002",
                check=False)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("exceeds the chord tolerance", r.stderr)
        self.assertIn("the file's own B-rep tolerance", r.stderr)
        self.assertTrue(os.path.exists(self.path("n.obj")))
        self.assertFalse(load_json(self.path("n.cad.json"))["tolerance_held"])

    def test_a_truncated_file_is_a_clear_error(self):
        with open(NIST, "rb") as f:
            head = f.read(60000)
        with open(self.path("cut.stp"), "wb") as f:
            f.write(head)
        r = cli("cad", "--in", self.path("cut.stp"), "--out", self.path("cut.obj"), check=False)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cut.stp", r.stderr)
        self.assertFalse(os.path.exists(self.path("cut.obj")))

    def test_an_out_that_is_not_obj_is_refused_before_any_work(self):
        # The mesh is OBJ; named .ply it would be read back as PLY and refused.
        r = cli("cad", "--in", BRACKET, "--out", self.path("b.ply"), check=False)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("must end in .obj", r.stderr + r.stdout)
        self.assertFalse(os.path.exists(self.path("b.ply")))

    def test_holes_lists_the_rims_of_a_step_solid(self):
        cli("cad", "--in", BRACKET, "--out", self.path("b.obj"))
        r = cli("holes", self.path("b.obj"))
        self.assertRegex(r.stdout, r"^[1-9]\d* holes and slots in ")

    def test_errormap_against_a_step_part_and_a_face_region(self):
        cli("cad", "--in", BRACKET, "--out", self.path("b.obj"))
        write_json(self.path("pose.json"), BRACKET_POSE)
        write_json(self.path("id.json"), IDENTITY)
        cli("simulate", "--mesh", self.path("b.obj"), "--world-from-part", self.path("pose.json"),
            "--world-from-sensor", self.path("id.json"), "--out", self.path("scan.pcd"),
            "--noise", "0.005", "--seed", "3")
        # The sensor looks along +z at the part turned over: its faces facing
        # -z in the part frame face the sensor.
        top = largest_face_facing(obj_faces(self.path("b.obj")), 2, +1)
        side = largest_face_facing(obj_faces(self.path("b.obj")), 0, +1)
        write_json(self.path("plan.json"), {
            "schema": "surfinspect.plan/1", "tolerance_mm": {"lower": -0.05, "upper": 0.05},
            "regions": [{"name": "top", "select": {"group": top}},
                        {"name": "side", "select": {"group": side}},
                        {"name": "body", "select": {"group": "body:l-bracket"}}]})
        r = cli("errormap", "--cloud", self.path("scan.pcd"), "--mesh", BRACKET,
                "--cad-cache", self.path("cache"), "--world-from-part", self.path("pose.json"),
                "--plan", self.path("plan.json"), "--out", self.path("em.ply"),
                "--report", self.path("em.json"))
        self.assertIn("tessellated", r.stderr)
        report = load_json(self.path("em.json"))
        self.assertEqual(report["cad"]["source"], os.path.basename(BRACKET))
        self.assertLessEqual(report["cad"]["tessellation_error_mm"], 0.01)
        chars = {c["name"]: c for c in report["characteristics"]}
        surface = chars["surface"]["points"]
        self.assertEqual(chars["body"]["points"], surface)
        self.assertGreater(chars["top"]["points"], 100)
        self.assertLess(chars["top"]["points"], surface)
        self.assertEqual(chars["top"]["verdict"], "pass")
        # A face the sensor cannot see (its normal across the view) has few points.
        self.assertLess(chars["side"]["points"], chars["top"]["points"])
        # --units is the cloud's alone with a STEP part; --mesh-units is refused.
        again = cli("errormap", "--cloud", self.path("scan.pcd"), "--mesh", BRACKET,
                    "--cad-cache", self.path("cache"), "--world-from-part", self.path("pose.json"),
                    "--units", "mm", "--out", self.path("em2.ply"), "--report", self.path("em2.json"))
        self.assertIn("cached tessellation reused", again.stderr)
        self.assertEqual(load_json(self.path("em2.json"))["input_units"]["cloud_stated"], True)
        refused = cli("errormap", "--cloud", self.path("scan.pcd"), "--mesh", BRACKET,
                      "--cad-cache", self.path("cache"), "--mesh-units", "in",
                      "--out", self.path("em3.ply"), check=False)
        self.assertEqual(refused.returncode, 1)
        self.assertIn("declares its own unit", refused.stderr)


def truth_cell(root, edit):
    """The demo cell in root/cell at SENSOR_PX, calibrated with the true poses
    and changed by edit(cell dict); returns its cell.json."""
    cell = os.path.join(root, "cell")
    subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", cell, "--parts", "0"],
                   check=True, stdout=subprocess.DEVNULL)
    cell_json = os.path.join(cell, "cell.json")
    c = load_json(cell_json)
    for vp in c["viewpoints"]:
        vp["world_from_sensor"] = vp["simulation_truth_world_from_sensor"]
    edit(c)
    write_json(cell_json, c)
    soak.shrink_sensor(cell_json, *soak.SENSOR_PX)
    return cell_json


def step_cell(root, part, plan=None, cad=None):
    """The truth cell with a STEP file as its part."""
    return truth_cell(root, lambda c: with_step_part(c, os.path.join(root, "cell"), part, plan, cad))


def with_step_part(c, cell, part, plan, cad):
    c["part"] = {"mesh": part, "world_from_part": NIST_POSE}
    c.pop("plan")
    if plan:
        c["plan"] = write_json(os.path.join(cell, "step-plan.json"), plan)
    if cad:
        c["cad"] = cad


def run_agent(cell_json, root, port, env=None):
    return subprocess.run(
        [os.path.join(BIN, "cell-agent"), "run", "--cell", cell_json,
         "--server", f"127.0.0.1:{port}", "--inbox", os.path.join(root, "inbox"),
         "--results", os.path.join(root, "results"), "--quarantine", os.path.join(root, "quarantine"),
         "--once", "--timeout", "60"],
        capture_output=True, text=True, env={**os.environ, **(env or {})}, timeout=300)


@unittest.skipUnless(os.path.isdir(REAL), f"SKIPPED: real CAD files absent ({REAL})")
class StepCellTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="cad-cell-")
        plan = {"schema": "surfinspect.plan/1", "tolerance_mm": {"lower": -0.3, "upper": 0.3},
                "regions": [{"name": "body", "select": {"group": "body:SOLID"}}]}
        cls.cell_json = step_cell(cls.root, NIST, plan)
        cls.parts = soak.stage_parts(cls.root, cls.cell_json, 3, seed=11)

    def test_inspect_tessellates_once_then_reuses_the_cache(self):
        out = os.path.join(self.root, "inspect")
        first = cli("inspect", "--cell", self.cell_json, "--scans", self.parts[0],
                    "--out", os.path.join(out, "1"), check=False)
        second = cli("inspect", "--cell", self.cell_json, "--scans", self.parts[1],
                     "--out", os.path.join(out, "2"), check=False)
        # The staging run already tessellated into the cell's cache.
        for r in (first, second):
            self.assertIn(r.returncode, (0, 1), r.stderr)
            self.assertIn("nist_ctc_01_asme1_ap242-e1.stp: cached tessellation reused", r.stderr)
        report = load_json(os.path.join(out, "2", "report.json"))
        self.assertEqual(report["cad"]["format"], "STEP")
        self.assertEqual(report["cad"]["declared_unit"], "MILLIMETRE")
        self.assertLessEqual(report["cad"]["tessellation_error_mm"], 0.01)
        # The scans were simulated from the same mesh at its true pose: the
        # bulk of the points lies on it (mixed pixels at pocket edges aside).
        stats = report["statistics"]
        self.assertLess(abs(stats["p50_mm"]), 0.01)
        self.assertLess(max(-stats["p5_mm"], stats["p95_mm"]), 0.1)
        chars = {c["name"]: c for c in report["characteristics"]}
        self.assertEqual(chars["body"]["points"], chars["surface"]["points"])

    def test_the_agent_reuses_the_cache_and_reports_the_cad(self):
        root = tempfile.mkdtemp(prefix="cad-agent-", dir=self.root)
        for i, p in enumerate(self.parts):
            soak.drop_part(p, os.path.join(root, "inbox"), f"step-{i}")
        port = soak.free_port()
        server = soak.start_server(port, os.path.join(root, "server.log"))
        try:
            r = run_agent(self.cell_json, root, port)
        finally:
            soak.stop(server)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertIn("cached tessellation reused", r.stderr)
        done = sorted(os.listdir(os.path.join(root, "results")))
        self.assertEqual([d for d in done if d.startswith("step-")], ["step-0", "step-1", "step-2"])
        for d in ("step-0", "step-1", "step-2"):
            report = load_json(os.path.join(root, "results", d, "report.json"))
            self.assertEqual(report["cad"]["source"], os.path.basename(NIST))


@unittest.skipUnless(os.path.isdir(REAL), f"SKIPPED: real CAD files absent ({REAL})")
class UnimportablePartTests(unittest.TestCase):
    """The part cannot be imported: every part is quarantined with the reason,
    and the agent finishes its round instead of stopping."""

    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="cad-bad-")
        good = step_cell(os.path.join(cls.root, "good"), NIST)
        cls.parts = soak.stage_parts(os.path.join(cls.root, "good"), good, 2, seed=5)

    def quarantined(self, part, cad=None, env=None):
        root = tempfile.mkdtemp(prefix="case-", dir=self.root)
        cell_json = step_cell(root, part, cad=cad)
        for i, p in enumerate(self.parts):
            soak.drop_part(p, os.path.join(root, "inbox"), f"bad-{i}")
        port = soak.free_port()
        server = soak.start_server(port, os.path.join(root, "server.log"))
        try:
            r = run_agent(cell_json, root, port, env)
        finally:
            soak.stop(server)
        self.assertEqual(r.returncode, 3, r.stderr)  # 3 = something was quarantined
        reasons = []
        for i in range(len(self.parts)):
            with open(os.path.join(root, "quarantine", f"bad-{i}", "error.txt")) as f:
                reasons.append(f.read())
        return r.stdout + r.stderr, reasons

    def test_a_truncated_step_part_quarantines_each_part(self):
        cut = os.path.join(self.root, "cut.stp")
        with open(NIST, "rb") as f, open(cut, "wb") as g:
            g.write(f.read(60000))
        log, reasons = self.quarantined(cut)
        for reason in reasons:
            self.assertIn("the cell's part could not be imported", reason)
            self.assertIn("cut.stp", reason)
        self.assertIn("summary: 0 parts done", log)

    def test_a_hanging_worker_is_stopped_at_the_cells_timeout(self):
        hang = os.path.join(self.root, "hang.sh")
        with open(hang, "w") as f:
            f.write("#!/bin/sh\nexec sleep 600\n")
        os.chmod(hang, 0o755)
        log, reasons = self.quarantined(NIST, cad={"timeout_s": 1},
                                        env={"SURFINSPECT_CAD_WORKER": hang})
        for reason in reasons:
            self.assertIn("the cell's part could not be imported", reason)
            self.assertIn("1 s", reason)


def main():
    global BIN
    BIN = sys.argv.pop(1)
    soak.BIN = BIN
    unittest.main(verbosity=2)


if __name__ == "__main__":
    main()
