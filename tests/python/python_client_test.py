#!/usr/bin/env python3
"""The Python client for MES integrators (client/python) against a real
surfinspectd: stubs generated from the proto with Debian's tools, the example
script's verdict and report equal to the C++ CLI's for the same part, the
mesh hash equal to the C++ one (a hash-only call hits the mesh the C++ client
cached), the token enforced, and bad input rejected with a clear message.
Its PCD and STL readers are checked on small hand-made files.

Run with Debian's /usr/bin/python3 (python3-grpcio, python3-protobuf).
usage: python_client_test.py BIN_DIR SOURCE_DIR [unittest args]
"""
import json
import math
import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import unittest
import urllib.request

BIN = SRC = None


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    def __init__(self, *extra):
        self.metrics_port = free_port()
        self.proc = subprocess.Popen(
            [os.path.join(BIN, "surfinspectd"), "--listen", "127.0.0.1:0", "--threads", "2",
             "--metrics-listen", f"127.0.0.1:{self.metrics_port}", *extra],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        line = self.proc.stdout.readline()
        self.proc.stdout.close()
        assert "listening on" in line, f"server did not start: {line!r}"
        self.target = line.split()[-1]

    def rpcs(self, method, codes):
        """surfinspect_rpcs_total for `method` summed over `codes`."""
        with urllib.request.urlopen(f"http://127.0.0.1:{self.metrics_port}/metrics", timeout=5) as r:
            text = r.read().decode()
        total = 0.0
        for code, m, value in re.findall(r'^surfinspect_rpcs_total\{code="([^"]*)",method="(\w+)"\} (\S+)$',
                                         text, re.M):
            if m == method and code in codes:
                total += float(value)
        return total

    def stop(self):
        # SIGKILL: graceful drain is tested elsewhere, and stopping the
        # metrics listener gracefully takes ~2 s.
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=30)


# The server labels Inspect's codes by number, the unary methods by name.
FAILED_PRECONDITION = ("FAILED_PRECONDITION", "9")


class PythonClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="py-client-")
        cls.gen = os.path.join(cls.root, "gen")
        subprocess.run([os.path.join(SRC, "client", "python", "generate.sh"), cls.gen], check=True,
                       stdout=subprocess.DEVNULL)
        sys.path[:0] = [cls.gen, os.path.join(SRC, "client", "python")]
        cls.token = os.path.join(cls.root, "token")
        with open(cls.token, "w") as f:
            f.write("py-client-test-token\n")
        subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", os.path.join(cls.root, "cell"),
                        "--parts", "1"], check=True, stdout=subprocess.DEVNULL)
        cls.cell = os.path.join(cls.root, "cell", "cell.json")
        cls.scans = os.path.join(cls.root, "cell", "scans", "part-001")
        server = Server("--auth-token-file", cls.token)
        try:
            out = subprocess.run([os.path.join(BIN, "cell-agent"), "calibrate", "--cell", cls.cell, "--server",
                                  server.target, "--token-file", cls.token],
                                 check=True, capture_output=True, text=True).stdout
        finally:
            server.stop()
        assert "calibrated 5 of 5" in out, out

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def setUp(self):
        self.server = None

    def tearDown(self):
        if self.server:
            self.server.stop()

    def example(self, *args, cell=None, scans=None, server=None):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([self.gen, os.path.join(SRC, "client", "python")]))
        cmd = [sys.executable, os.path.join(SRC, "client", "python", "inspect_part.py"),
               "--cell", cell or self.cell, "--scans", scans or self.scans,
               "--server", server or self.server.target, *args]
        return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=120)

    def test_stubs_are_generated_from_the_proto(self):
        for f in ("inspection_pb2.py", "inspection_pb2_grpc.py"):
            self.assertTrue(os.path.exists(os.path.join(self.gen, "surfinspect", "v1", f)), f)
        from surfinspect.v1 import inspection_pb2_grpc
        self.assertTrue(hasattr(inspection_pb2_grpc, "InspectionServiceStub"))

    def test_example_matches_the_cpp_cli_and_its_mesh_hash(self):
        self.server = Server("--auth-token-file", self.token)
        out_dir = os.path.join(self.root, "cpp-out")
        # The C++ CLI first: its (small) part mesh goes inline and the server
        # caches it under the hash it computes itself.
        subprocess.run([os.path.join(BIN, "surfinspect"), "inspect", "--cell", self.cell, "--scans", self.scans,
                        "--out", out_dir, "--server", self.server.target, "--token-file", self.token],
                       check=True, capture_output=True, text=True)
        self.assertEqual(self.server.rpcs("Inspect", FAILED_PRECONDITION), 0)
        # Python by hash only: a hit, so the Python mesh and hash equal C++'s.
        report_path = os.path.join(self.root, "py-report.json")
        r = self.example("--token-file", self.token, "--mesh", "hash", "--report", report_path)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertEqual(self.server.rpcs("Inspect", FAILED_PRECONDITION), 0,
                         "the Python client's mesh hash differs from the C++ client's")
        self.assertEqual(self.server.rpcs("Inspect", ("OK",)), 2)
        with open(report_path) as f:
            py = json.load(f)
        with open(os.path.join(out_dir, "report.json")) as f:
            cpp = json.load(f)
        py.pop("timing", None)
        cpp.pop("timing", None)
        # The CLI records the units it read the files in (docs/units.md); the
        # server's report, which the Python client writes, has no files.
        self.assertEqual(cpp.pop("input_units")["doubts"], [])
        self.assertEqual(py, cpp)
        # The exit code and the first line are the part verdict (the typed field).
        verdict = cpp["verdict"]
        self.assertEqual(r.returncode, 0 if verdict == "pass" else 1)
        failed = [c["name"] for c in cpp["characteristics"] if c["verdict"] == "fail"]
        self.assertEqual(re.findall(r"^  failed ([^:]+):", r.stdout, re.M), failed)
        unseen = [c["name"] for c in cpp["characteristics"] if c["verdict"] == "not_measured"]
        self.assertEqual(re.findall(r"^  not measured ([^:]+):", r.stdout, re.M), unseen)
        self.assertEqual(len(re.findall(r"^  defect ", r.stdout, re.M)), len(cpp["defects"]))
        self.assertRegex(r.stdout, rf"(?m)^part-001 {verdict}  min [-+]\d+\.\d{{3}} mm  max [-+]\d+\.\d{{3}} mm$")
        self.assertIn(f"{cpp['statistics']['max_mm']:+.3f}", r.stdout)

    def test_hash_miss_falls_back_to_inline(self):
        self.server = Server()
        r = self.example("--mesh", "hash")
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertEqual(self.server.rpcs("Inspect", FAILED_PRECONDITION), 1)
        self.assertEqual(self.server.rpcs("Inspect", ("OK",)), 1)
        r = self.example()  # auto: this mesh is small next to the clouds, inline
        self.assertIn(r.returncode, (0, 1), r.stderr)
        self.assertEqual(self.server.rpcs("Inspect", FAILED_PRECONDITION), 1)

    def test_token_is_required(self):
        self.server = Server("--auth-token-file", self.token)
        r = self.example()
        self.assertEqual(r.returncode, 2)
        self.assertIn("UNAUTHENTICATED", r.stderr)
        self.assertNotIn("Traceback", r.stderr)

    def test_bad_input_is_rejected_clearly(self):
        self.server = Server()
        bad = os.path.join(self.root, "bad-part")
        shutil.copytree(self.scans, bad)
        with open(os.path.join(bad, "v2.pcd"), "r+b") as f:
            f.truncate(os.path.getsize(os.path.join(bad, "v2.pcd")) // 2)
        r = self.example(scans=bad)
        self.assertEqual(r.returncode, 2)
        self.assertIn("truncated", r.stderr)
        # The cell before calibration has no world_from_sensor.
        r = self.example(cell=self.cell + ".bak")
        self.assertEqual(r.returncode, 2)
        self.assertIn("not calibrated", r.stderr)
        empty = os.path.join(self.root, "empty-part")
        os.makedirs(empty, exist_ok=True)
        r = self.example(scans=empty)
        self.assertEqual(r.returncode, 2)
        self.assertIn("no <viewpoint>.pcd", r.stderr)
        # Nobody listening: the deadline, not a hang.
        r = self.example("--timeout", "2", server=f"127.0.0.1:{free_port()}")
        self.assertEqual(r.returncode, 2)
        self.assertRegex(r.stderr, "DEADLINE_EXCEEDED|UNAVAILABLE")
        self.assertEqual(self.server.rpcs("Inspect", ("OK",)), 0)

    def test_plan_alignment_goes_into_the_typed_plan(self):
        import surfinspect_client as sc
        from surfinspect.v1 import inspection_pb2 as pb
        msg = sc.plan_proto({"alignment": {
            "mode": "rps", "max_correction_mm": 1.5,
            "references": [{"name": "A1", "hole": "H1"},
                           {"name": "B1", "position_mm": [1, 2, 3], "radius_mm": 4}]}})
        a = msg.alignment
        self.assertEqual(a.mode, pb.ALIGNMENT_MODE_RPS)
        self.assertEqual(a.max_correction_mm, 1.5)
        self.assertFalse(a.HasField("max_correction_deg"))
        self.assertEqual([(r.name, r.hole) for r in a.references], [("A1", "H1"), ("B1", "")])
        self.assertEqual(list(a.references[1].position_mm), [1, 2, 3])
        self.assertEqual(a.references[1].radius_mm, 4)
        fit = sc.plan_proto({"alignment": {"mode": "best_fit", "regions": ["ridge"],
                                           "locked": ["tz", "rx"]}}).alignment
        self.assertEqual((fit.mode, list(fit.regions), list(fit.locked)),
                         (pb.ALIGNMENT_MODE_BEST_FIT, ["ridge"], ["tz", "rx"]))
        self.assertFalse(sc.plan_proto({}).HasField("alignment"))
        for bad, message in (({"mode": "wobble"}, "plan.alignment.mode: must be"),
                             ({"mode": "rps", "stiff": 1}, "plan.alignment.stiff: unknown key"),
                             ({"mode": "best_fit", "locked": "tz"}, "plan.alignment.locked: must be an array"),
                             ({"mode": "rps", "references": [{"name": "A", "position_mm": [1, 2]}]},
                              r"plan.alignment.references\[0\].position_mm: must be an array of 3")):
            with self.assertRaisesRegex(sc.ClientError, message):
                sc.plan_proto({"alignment": bad})

    def test_pcd_reader_ascii_binary_and_interleaved_fields(self):
        import surfinspect_client as sc
        pts = [(1.5, -2.25, 300.0), (math.nan, math.nan, math.nan), (0.125, 4.0, -7.5)]
        expect = b"".join(struct.pack("<3f", *p) for p in pts)

        def header(fields, size, typ, count, encoding):
            return (f"VERSION 0.7\nFIELDS {fields}\nSIZE {size}\nTYPE {typ}\nCOUNT {count}\n"
                    f"WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA {encoding}\n").encode()
        cases = {
            "ascii": header("x y z", "4 4 4", "F F F", "1 1 1", "ascii") +
            b"".join(b"%r %r %r\n" % p for p in pts),
            "binary": header("x y z", "4 4 4", "F F F", "1 1 1", "binary") + expect,
            # intensity before x, a uint8 label after z: picked out per point
            "interleaved": header("intensity x y z label", "4 4 4 4 1", "F F F F U", "1 1 1 1 1", "binary") +
            b"".join(struct.pack("<f3fB", 9.0, *p, 7) for p in pts),
        }
        for name, data in cases.items():
            path = os.path.join(self.root, name + ".pcd")
            with open(path, "wb") as f:
                f.write(data)
            xyz, w, h = sc.read_pcd(path)
            self.assertEqual((w, h), (3, 1), name)
            got = struct.unpack("<9f", xyz)
            want = struct.unpack("<9f", expect)
            for a, b in zip(got, want):
                self.assertTrue(a == b or (math.isnan(a) and math.isnan(b)), f"{name}: {got} != {want}")
        with open(os.path.join(self.root, "short.pcd"), "wb") as f:
            f.write(cases["binary"][:-5])
        with self.assertRaisesRegex(sc.ClientError, "truncated"):
            sc.read_pcd(os.path.join(self.root, "short.pcd"))
        with open(os.path.join(self.root, "huge.pcd"), "wb") as f:
            f.write(header("x y z", "4 4 4", "F F F", "1 1 1", "binary").replace(b"WIDTH 3", b"WIDTH 4000000000"))
        with self.assertRaisesRegex(sc.ClientError, "bad PCD sizes"):
            sc.read_pcd(os.path.join(self.root, "huge.pcd"))

    def test_stl_reader_merges_identical_vertices_in_ascii_and_binary(self):
        import surfinspect_client as sc
        # Two triangles sharing the edge (1,0,0)-(0,1,0): 4 vertices, not 6.
        tris = [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((1, 0, 0), (1, 1, 0), (0, 1, 0))]
        binary = b"\0" * 80 + struct.pack("<I", 2) + b"".join(
            struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *v) for v in t) + b"\0\0" for t in tris)
        ascii_stl = "solid t\n" + "".join(
            "facet normal 0 0 1\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in t) +
            "endloop\nendfacet\n" for t in tris) + "endsolid t\n"
        results = []
        for name, data in (("b.stl", binary), ("a.stl", ascii_stl.encode())):
            path = os.path.join(self.root, name)
            with open(path, "wb") as f:
                f.write(data)
            results.append(sc.read_stl(path))
        self.assertEqual(results[0], results[1])
        vertices, triangles = results[0]
        self.assertEqual(len(vertices), 4 * 12)
        self.assertEqual(struct.unpack("<6I", triangles), (0, 1, 2, 1, 3, 2))
        with open(os.path.join(self.root, "junk.stl"), "wb") as f:
            f.write(b"\x01" * 90)
        with self.assertRaisesRegex(sc.ClientError, "not an STL"):
            sc.read_stl(os.path.join(self.root, "junk.stl"))

    def test_readers_refuse_malformed_files_with_a_message(self):
        import surfinspect_client as sc

        def pcd(body):
            return (b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                    b"WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n" + body)
        two = struct.pack("<6f", 1, 2, 3, 4, 5, 6)
        bad_pcd = {
            "not a keyword first": (b"hello\n" + pcd(b"DATA binary\n" + two), "unknown PCD header"),
            "garbage COUNT, second header": (
                pcd(b"DATA binary\n" + two).replace(b"COUNT 1 1 1", b"COUNT a b c") +
                b"VERSION 0.7\n", "malformed PCD header"),
            "repeated key": (pcd(b"WIDTH 2\nDATA binary\n" + two), "repeated or out of order"),
            "negative sizes": (pcd(b"DATA binary\n").replace(b"WIDTH 2", b"WIDTH -2")
                               .replace(b"HEIGHT 1", b"HEIGHT -1"), "positive integer"),
            "POINTS disagrees": (pcd(b"DATA binary\n" + two).replace(b"POINTS 2", b"POINTS 3"),
                                 "POINTS is not"),
            "fields disagree": (pcd(b"DATA binary\n" + two).replace(b"SIZE 4 4 4", b"SIZE 4 4"),
                                "bad PCD sizes"),
            "infinite point": (pcd(b"DATA ascii\n1 2 3\ninf 5 6\n"), "infinite"),
            "short ascii row": (pcd(b"DATA ascii\n1 2 3\n44 55\n"), "bad point line"),
            "no DATA": (b"# a comment\n" * 10000, "truncated PCD header"),
        }
        for name, (data, message) in bad_pcd.items():
            path = os.path.join(self.root, "bad.pcd")
            with open(path, "wb") as f:
                f.write(data)
            with self.assertRaisesRegex(sc.ClientError, message, msg=name):
                sc.read_pcd(path)
        quad = ("solid q\nfacet normal 0 0 1\nouter loop\n" +
                "".join(f"vertex {x} {y} 0\n" for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))) +
                "endloop\nendfacet\nendsolid q\n")
        bad_stl = {"quad facet": (quad, "facet with 4 vertices"),
                   "nan vertex": (quad.replace("vertex 0 1 0\n", "").replace("vertex 1 1 0", "vertex nan 1 0"),
                                  "not finite")}
        for name, (text, message) in bad_stl.items():
            path = os.path.join(self.root, "bad.stl")
            with open(path, "w") as f:
                f.write(text)
            with self.assertRaisesRegex(sc.ClientError, message, msg=name):
                sc.read_stl(path)

    def test_cell_numbers_out_of_range_are_refused_not_wrapped(self):
        import surfinspect_client as sc
        for section, key, value in (("filter", "min_cluster_points", -5), ("filter", "connectivity", 1e300),
                                    ("error_map", "histogram_bins", 1e300), ("filter", "link_distance_mm", "x")):
            cell = {"world_from_part": None, "tolerance_mm": None, "error_map": {}, "filter": {}}
            cell[section] = {key: value}
            with self.assertRaisesRegex(sc.ClientError, f"{section}.{key}", msg=f"{key}={value!r}"):
                sc._header(cell, "p", None)

    def test_resource_exhausted_is_retried_with_jittered_backoff_up_to_max_attempts(self):
        import grpc
        import surfinspect_client as sc
        # A 1 MiB budget refuses the demo part's views at every call.
        self.server = Server("--auth-token-file", self.token, "--max-memory-mb", "1")
        with open(self.token) as f:
            token = f.read().strip()
        waits, retries = [], []
        with sc.connect(self.server.target) as channel:
            with self.assertRaises(grpc.RpcError) as ctx:
                sc.inspect_part(channel, sc.read_cell(self.cell), self.scans, "part-001", token=token,
                                max_attempts=4, backoff_initial_s=0.5, backoff_max_s=0.75,
                                on_retry=lambda e, calls, wait: retries.append((e.code(), calls)),
                                sleep=waits.append)
        self.assertEqual(ctx.exception.code(), grpc.StatusCode.RESOURCE_EXHAUSTED)
        self.assertIn("memory budget", ctx.exception.details())
        self.assertEqual(retries, [(grpc.StatusCode.RESOURCE_EXHAUSTED, n) for n in (1, 2, 3)])
        # Full jitter: retry n waits uniform in [0, min(max, initial * 2^n)].
        self.assertEqual(len(waits), 3)
        for wait, cap in zip(waits, (0.5, 0.75, 0.75)):
            self.assertTrue(0 <= wait <= cap, (wait, cap))
        self.assertEqual(self.server.rpcs("Inspect", ("RESOURCE_EXHAUSTED", "8")), 4)


if __name__ == "__main__":
    BIN = os.path.abspath(sys.argv[1])
    SRC = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0]] + sys.argv[3:], verbosity=2)
