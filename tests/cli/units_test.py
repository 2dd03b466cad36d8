#!/usr/bin/env python3
"""Units, never guessed silently, on PCL's real Kinect and stereo clouds
(../shared/realdata/clouds, in metres; skipped loudly where absent):

- the same scan and mesh written in metres and in millimetres (converted
  here, independently of surfinspect: float32(float64(x) * 1000)) give the
  same error map with --units m and without it respectively;
- without --units, the metre files get a WARNING on stderr naming metres
  and the option, and the report carries the doubt; a mesh in metres
  against a scan in millimetres is doubted too;
- the filter in metres (--units m) writes the same bytes as the filter of
  the millimetre file, and with --out-units input its kept points are the
  input's bits;
- a cell whose scans are in metres: without "sensor.units" the agent
  quarantines each part with the doubt; with it, the parts are judged as
  the millimetre ones are.

usage: units_test.py BIN_DIR [unittest args]
"""
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "client", "agent"))
import agent_soak_test as soak  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cad_part_test as cad  # noqa: E402

BIN = None
REAL = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                     "..", "..", "..", "shared", "realdata", "clouds"))
KINECT = os.path.join(REAL, "pairwise__capture0001.pcd")
STEREO = os.path.join(REAL, "table_scene_mug_stereo_textured.pcd")
MESH_STEP = 8  # the mesh: the scan's own grid, every 8th pixel


def lzf_decompress(data, size):
    """LZF (liblzf's format, as PCL's binary_compressed uses it)."""
    out = bytearray()
    i = 0
    while i < len(data):
        ctrl = data[i]
        i += 1
        if ctrl < 32:
            out += data[i:i + ctrl + 1]
            i += ctrl + 1
            continue
        length = ctrl >> 5
        ref = len(out) - ((ctrl & 0x1f) << 8) - 1
        if length == 7:
            length += data[i]
            i += 1
        ref -= data[i]
        i += 1
        for _ in range(length + 2):
            out.append(out[ref])
            ref += 1
    assert len(out) == size
    return bytes(out)


def read_pcd_xyz(path):
    """(width, height, [(x, y, z)]) of a PCD with float x y z among its fields."""
    with open(path, "rb") as f:
        data = f.read()
    header, pos = {}, 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode().strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key] = value.split()
        if key == "DATA":
            break
    fields, sizes = header["FIELDS"], [int(s) for s in header["SIZE"]]
    counts = [int(c) for c in header.get("COUNT", ["1"] * len(fields))]
    n = int(header["POINTS"][0])
    width, height = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
    xyz = [fields.index(a) for a in "xyz"]
    kind = header["DATA"][0]
    if kind == "binary_compressed":
        packed, raw = struct.unpack_from("<II", data, pos)
        planes = lzf_decompress(data[pos + 8:pos + 8 + packed], raw)
        offsets, off = [], 0
        for s, c in zip(sizes, counts):
            offsets.append(off)
            off += s * c * n
        cols = [struct.unpack_from(f"<{n}f", planes, offsets[k]) for k in xyz]
    else:
        assert kind == "binary", kind
        stride = sum(s * c for s, c in zip(sizes, counts))
        field_off = [sum(s * c for s, c in zip(sizes[:k], counts[:k])) for k in range(len(fields))]
        cols = [[struct.unpack_from("<f", data, pos + i * stride + field_off[k])[0] for i in range(n)]
                for k in xyz]
    return width, height, list(zip(*cols))


def f32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def to_mm(points):
    """float32(float64(x) * 1000), NaN kept: what a millimetre file of the scan holds."""
    return [tuple(f32(c * 1000.0) for c in p) for p in points]


def write_pcd(path, width, height, points):
    header = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
              f"TYPE F F F\nCOUNT 1 1 1\nWIDTH {width}\nHEIGHT {height}\n"
              f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\nDATA binary\n")
    with open(path, "wb") as f:
        f.write(header.encode())
        for p in points:
            f.write(struct.pack("<3f", *p))


def grid_mesh(width, height, points, step):
    """Triangles of the scan's grid every `step` pixels, where all corners are valid."""
    tris = []
    for r in range(0, height - step, step):
        for c in range(0, width - step, step):
            a, b = points[r * width + c], points[r * width + c + step]
            d, e = points[(r + step) * width + c], points[(r + step) * width + c + step]
            for t in ((a, b, e), (a, e, d)):
                if all(not math.isnan(v) for p in t for v in p):
                    tris.append(t)
    return tris


def write_stl(path, tris):
    with open(path, "wb") as f:
        f.write(b"surfinspect units test".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0, 0, 0))
            for p in t:
                f.write(struct.pack("<3f", *p))
            f.write(b"\0\0")


def run(*args, check=True):
    r = subprocess.run([os.path.join(BIN, "surfinspect"), *args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"surfinspect {' '.join(args)}: exit {r.returncode}\n{r.stderr}")
    return r


def load(path):
    with open(path) as f:
        return json.load(f)


def judged(report):
    """The report without what depends on file names, timing and the units line."""
    return {k: v for k, v in report.items() if k not in ("timing", "inputs", "input_units")}


@unittest.skipUnless(os.path.isdir(REAL), f"SKIPPED: real clouds absent ({REAL})")
class ErrorMapUnitsTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="units-")
        w, h, pts = read_pcd_xyz(KINECT)
        tris = grid_mesh(w, h, pts, MESH_STEP)
        write_pcd(cls.path("scan_m.pcd"), w, h, pts)
        write_pcd(cls.path("scan_mm.pcd"), w, h, to_mm(pts))
        write_stl(cls.path("mesh_m.stl"), tris)
        write_stl(cls.path("mesh_mm.stl"), [to_mm(t) for t in tris])

    @classmethod
    def path(cls, name):
        return os.path.join(cls.dir, name)

    def errormap(self, cloud, mesh, name, *units):
        r = run("errormap", "--cloud", self.path(cloud), "--mesh", self.path(mesh),
                "--max-distance", "100", "--tolerance", "5", "--out", self.path(name + ".ply"),
                "--report", self.path(name + ".json"), *units)
        return r, load(self.path(name + ".json"))

    def test_metres_with_units_equals_millimetres_without(self):
        rm, metres = self.errormap("scan_m.pcd", "mesh_m.stl", "m", "--units", "m")
        rmm, mm = self.errormap("scan_mm.pcd", "mesh_mm.stl", "mm")
        for r in (rm, rmm):
            self.assertNotIn("WARNING", r.stderr)
        self.assertEqual(judged(metres), judged(mm))
        # Real deviations of millimetres, not thousandths of one.
        self.assertGreater(mm["statistics"]["rms_mm"], 1.0)
        self.assertEqual(metres["input_units"], {"cloud": "m", "cloud_stated": True, "mesh": "m",
                                                 "mesh_stated": True, "doubts": []})
        self.assertEqual(mm["input_units"]["cloud"], "mm")
        self.assertFalse(mm["input_units"]["cloud_stated"])
        self.assertEqual(mm["input_units"]["doubts"], [])
        with open(self.path("m.ply"), "rb") as f:
            self.assertIn(b"comment units: mm\n", f.read(400))

    def test_metres_without_units_are_doubted_loudly(self):
        r, report = self.errormap("scan_m.pcd", "mesh_m.stl", "silent")
        self.assertIn("WARNING:", r.stderr)
        self.assertIn("look like metres", r.stderr)
        self.assertIn("--cloud-units m", r.stderr)
        self.assertIn("--mesh-units m", r.stderr)
        self.assertIn("units: DOUBTED", r.stdout)
        self.assertEqual(len(report["input_units"]["doubts"]), 2)
        # The same numbers 1000 times too small: why the doubt matters.
        _, mm = self.errormap("scan_mm.pcd", "mesh_mm.stl", "mm-again")
        self.assertAlmostEqual(report["statistics"]["p50_mm"] * 1000, mm["statistics"]["p50_mm"],
                               delta=1e-3 * abs(mm["statistics"]["p50_mm"]) + 1e-3)

    def test_a_mesh_in_metres_against_a_scan_in_millimetres(self):
        r, report = self.errormap("scan_mm.pcd", "mesh_m.stl", "mixed", "--cloud-units", "mm")
        self.assertIn("WARNING:", r.stderr)
        [doubt] = report["input_units"]["doubts"]
        self.assertIn("mesh", doubt)
        self.assertIn("--mesh-units m", doubt)

    def test_the_filter_reads_metres_and_writes_millimetres_or_the_input_as_read(self):
        w, h, pts = read_pcd_xyz(STEREO)
        write_pcd(self.path("stereo_mm.pcd"), w, h, to_mm(pts))
        common = ("--link-distance", "5", "--min-cluster", "50")  # removes ~1000 points
        run("filter", "--in", STEREO, "--out", self.path("f_m.pcd"), "--units", "m", *common)
        r = run("filter", "--in", self.path("stereo_mm.pcd"), "--out", self.path("f_mm.pcd"), *common)
        self.assertNotIn("WARNING", r.stderr)
        with open(self.path("f_m.pcd"), "rb") as a, open(self.path("f_mm.pcd"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        run("filter", "--in", STEREO, "--out", self.path("f_in.pcd"), "--units", "m",
            "--out-units", "input", "--report", self.path("f_in.json"), *common)
        _, _, kept = read_pcd_xyz(self.path("f_in.pcd"))
        _, _, filtered_mm = read_pcd_xyz(self.path("f_mm.pcd"))
        bits = lambda p: struct.pack("<3f", *p)  # noqa: E731
        removed = 0
        for src, out, mm in zip(pts, kept, filtered_mm):
            if math.isnan(out[0]):
                removed += not math.isnan(src[0])
                self.assertTrue(math.isnan(mm[0]))
            else:
                self.assertEqual(bits(out), bits(src))
        self.assertGreater(removed, 0)
        with open(self.path("f_in.pcd"), "rb") as f:
            self.assertIn(b"# units: m\n", f.read(200))
        units = load(self.path("f_in.json"))["units"]
        self.assertEqual((units["input"], units["output"], units["doubts"]), ("m", "m", []))
        r = run("filter", "--in", STEREO, "--out", self.path("f_doubt.pcd"), *common)
        self.assertIn("WARNING:", r.stderr)
        self.assertIn("--units m", r.stderr)


def metre_copy(source, dest):
    """A staged part's scans divided by 1000: what a sensor writing metres sends."""
    os.makedirs(dest)
    for name in soak.VIEWS:
        w, h, pts = read_pcd_xyz(os.path.join(source, name))
        write_pcd(os.path.join(dest, name), w, h, [tuple(f32(c / 1000.0) for c in p) for p in pts])
    open(os.path.join(dest, "DONE"), "w").close()


class AgentUnitsTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="units-agent-")
        cls.cell_json = cad.truth_cell(cls.root, lambda c: c.pop("units"))  # a cell that does not say
        cls.parts = soak.stage_parts(cls.root, cls.cell_json, 2, seed=21)

    def run_cell(self, name, sensor_units, metres):
        root = os.path.join(self.root, name)
        cell = load(self.cell_json)
        if sensor_units:
            cell["sensor"]["units"] = sensor_units
        cell_json = os.path.join(os.path.dirname(self.cell_json), name + ".json")
        with open(cell_json, "w") as f:
            json.dump(cell, f, indent=1)
        for i, p in enumerate(self.parts):
            dest = os.path.join(root, "inbox", f"{name}-{i}")
            if metres:
                metre_copy(p, dest)
            else:
                soak.drop_part(p, os.path.join(root, "inbox"), f"{name}-{i}")
        port = soak.free_port()
        server = soak.start_server(port, os.path.join(root, "server.log"))
        try:
            r = cad.run_agent(cell_json, root, port)
        finally:
            soak.stop(server)
        return root, r

    def test_scans_in_metres_without_units_are_quarantined(self):
        root, r = self.run_cell("nounits", None, metres=True)
        self.assertEqual(r.returncode, 3, r.stderr)
        for i in range(len(self.parts)):
            with open(os.path.join(root, "quarantine", f"nounits-{i}", "error.txt")) as f:
                why = f.read()
            self.assertIn("units in doubt", why)
            self.assertIn("look like metres", why)
            self.assertIn("sensor.units = m", why)
        self.assertIn("units in doubt", r.stderr)

    def test_scans_in_metres_with_units_are_judged_as_in_millimetres(self):
        root_m, r_m = self.run_cell("metres", "m", metres=True)
        root_mm, r_mm = self.run_cell("millimetres", None, metres=False)
        for r in (r_m, r_mm):
            self.assertIn(r.returncode, (0, 1), r.stderr)
        for i in range(len(self.parts)):
            m = load(os.path.join(root_m, "results", f"metres-{i}", "report.json"))
            mm = load(os.path.join(root_mm, "results", f"millimetres-{i}", "report.json"))
            self.assertEqual(m["input_units"]["cloud"], "m")
            self.assertTrue(m["input_units"]["cloud_stated"])
            self.assertEqual(mm["input_units"]["doubts"], [])
            self.assertEqual(m["verdict"], mm["verdict"])
            # float32 to metres and back moves a point by < 1e-4 mm.
            for k in ("p5_mm", "p50_mm", "p95_mm", "rms_mm"):
                self.assertAlmostEqual(m["statistics"][k], mm["statistics"][k], delta=1e-3)


def main():
    global BIN
    BIN = sys.argv.pop(1)
    soak.BIN = cad.BIN = BIN
    unittest.main(verbosity=2)


if __name__ == "__main__":
    main()
