#!/usr/bin/env python3
"""The memory budget under pressure: surfinspectd under a 4 GB address-space
limit (prlimit --as), whose default budget is then half of it, and twelve
concurrent Inspect streams of 20 M points each (one 5000 x 4000 view) from the
Python client (client/python). Every call ends OK or RESOURCE_EXHAUSTED (the
refusal comes at the view header, before the cloud is buffered), never
INTERNAL; the server answers the health check with SERVING during and after;
with the client's retries every part completes; and the server's peak
resident memory (VmHWM) stays under the budget plus MARGIN_BYTES.

The parts are cheap on purpose: a two-triangle plane, no filter, no
deviations, two worker threads. All twelve streams send the same bytes.

Run with Debian's /usr/bin/python3 (python3-grpcio, python3-protobuf).
usage: memory_pressure_test.py BIN_DIR SOURCE_DIR [unittest args]
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from array import array

BIN = SRC = None
ADDRESS_SPACE_BYTES = 4_000_000_000
PARTS = 12
WIDTH, HEIGHT = 5000, 4000  # 20 M points, 240 MB per stream
PLANE_MM = 1000.0
# Peak resident memory may pass the budget by the process's own share: its
# code and libraries, gRPC's buffers for the streams in flight (gRPC's
# ResourceQuota allows up to a quarter of the budget) and the fixed part of a
# call that the per-point figure does not cover.
MARGIN_BYTES = 256 << 20


def plane_cloud(width, height):
    """An organized grid 0.5 mm above the plane z = 0, as float32 xyz bytes."""
    row = array("f", [0.0, 0.0, 0.5]) * width
    row[0::3] = array("f", [PLANE_MM * (i + 0.5) / width for i in range(width)])
    out = bytearray()
    for j in range(height):
        row[1::3] = array("f", [PLANE_MM * (j + 0.5) / height]) * width
        out += row.tobytes()
    return bytes(out)


def write_plane_stl(path):
    """Binary STL of the square [0, PLANE_MM]^2 at z = 0: two triangles, normal +z."""
    s = PLANE_MM
    tris = [((0, 0, 0), (s, 0, 0), (s, s, 0)), ((0, 0, 0), (s, s, 0), (0, s, 0))]
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(tris)))
        for tri in tris:
            f.write(struct.pack("<3f", 0, 0, 1))
            for v in tri:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")


def memory(pid):
    """{VmRSS, VmHWM} of `pid` in bytes."""
    out = {}
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[key] = int(value.split()[0]) * 1024
    return out


def health_status(channel):
    """grpc.health.v1.Health/Check for the whole server: 1 = SERVING. The
    request is empty and the reply is field 1 (a varint), so no stubs."""
    check = channel.unary_unary("/grpc.health.v1.Health/Check", request_serializer=lambda m: m,
                                response_deserializer=lambda b: b)
    reply = check(b"", timeout=10)
    return reply[1] if len(reply) == 2 and reply[0] == 0x08 else 0


class MemoryPressureTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = tempfile.mkdtemp(prefix="mem-pressure-")
        gen = os.path.join(cls.root, "gen")
        subprocess.run([os.path.join(SRC, "client", "python", "generate.sh"), gen], check=True,
                       stdout=subprocess.DEVNULL)
        sys.path[:0] = [gen, os.path.join(SRC, "client", "python")]

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.root, ignore_errors=True)

    def start_server(self):
        self.log_path = os.path.join(self.root, "server.log")
        self.log = open(self.log_path, "w")
        self.server = subprocess.Popen(
            ["prlimit", f"--as={ADDRESS_SPACE_BYTES}", "--", os.path.join(BIN, "surfinspectd"),
             "--listen", "127.0.0.1:0", "--threads", "2"],
            stdout=subprocess.PIPE, stderr=self.log, text=True)
        line = self.server.stdout.readline()
        self.server.stdout.close()
        self.assertIn("listening on", line, "server did not start")
        self.target = line.split()[-1]
        deadline, m = time.monotonic() + 10, None
        while m is None and time.monotonic() < deadline:  # stderr may lag the stdout line
            with open(self.log_path) as f:
                m = re.search(r"memory budget (\d+) MiB", f.read())
            time.sleep(0.05)
        self.assertIsNotNone(m, "the server's start line names no memory budget")
        return int(m.group(1)) << 20

    def tearDown(self):
        if self.server.poll() is None:
            self.server.kill()
        self.server.wait(timeout=30)
        self.log.close()

    def test_twelve_20m_point_streams_under_4gb(self):
        import grpc
        import surfinspect_client as sc

        budget = self.start_server()
        # Half of the address-space limit (DetectMemoryLimits), in whole MiB.
        self.assertEqual(budget >> 20, (ADDRESS_SPACE_BYTES // 2) >> 20)
        # One stream fits the budget, two do not: the rest must be refused.
        self.assertLess(WIDTH * HEIGHT * 80, budget)
        self.assertGreater(2 * WIDTH * HEIGHT * 80, budget)

        mesh = os.path.join(self.root, "plane.stl")
        write_plane_stl(mesh)
        identity = sc.pb.Transform(row_major=[1.0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
        cell = {"part_mesh": mesh, "world_from_part": identity, "viewpoints": [("v0", identity)],
                "tolerance_mm": 1.0, "error_map": {}, "filter": {"enabled": False}}
        views = [("v0", identity, (plane_cloud(WIDTH, HEIGHT), WIDTH, HEIGHT))]
        # read_pcd checks every coordinate in Python, far too slow for 12 x 20 M
        # points; the streams send the views built above instead.
        sc.load_views = lambda cell_, scans_dir: views

        channel = sc.connect(self.target)
        codes, outcomes, lock = [], {}, threading.Lock()
        peak_rss, health_failures, stop = [0], [], threading.Event()

        def watch():
            while not stop.is_set():
                try:
                    peak_rss[0] = max(peak_rss[0], memory(self.server.pid)["VmRSS"])
                    if health_status(channel) != 1:
                        health_failures.append("not SERVING")
                except (OSError, grpc.RpcError) as e:
                    health_failures.append(repr(e))
                stop.wait(0.25)

        def on_retry(error, calls, wait_s):
            with lock:
                codes.append(error.code().name)

        def part(i):
            part_id = f"part-{i:02d}"
            try:
                result = sc.inspect_part(channel, cell, "unused", part_id, timeout_s=600, mesh="inline",
                                         max_attempts=200, backoff_initial_s=0.25, backoff_max_s=3.0,
                                         on_retry=on_retry)
                outcome = "OK" if result.verdict in ("pass", "fail") else "no verdict"
            except grpc.RpcError as e:
                outcome = f"{e.code().name}: {e.details()}"
            except Exception as e:  # noqa: BLE001 - reported as the part's outcome
                outcome = repr(e)
            with lock:
                codes.append(outcome.split(":")[0])
                outcomes[part_id] = outcome

        watcher = threading.Thread(target=watch)
        watcher.start()
        start = time.monotonic()
        threads = [threading.Thread(target=part, args=(i,)) for i in range(PARTS)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        wall_s = time.monotonic() - start
        stop.set()
        watcher.join()

        self.assertIsNone(self.server.poll(), "the server died")
        self.assertEqual(health_status(channel), 1, "not SERVING after the load")
        hwm = memory(self.server.pid)["VmHWM"]
        refused = codes.count("RESOURCE_EXHAUSTED")
        print(f"\n{PARTS} parts of {WIDTH * HEIGHT} points in {wall_s:.1f} s: {len(codes)} calls, "
              f"{codes.count('OK')} OK, {refused} RESOURCE_EXHAUSTED, "
              f"{len(codes) - codes.count('OK') - refused} other; server VmHWM {hwm >> 20} MiB, sampled "
              f"peak RSS {peak_rss[0] >> 20} MiB, budget {budget >> 20} MiB + margin {MARGIN_BYTES >> 20} MiB",
              file=sys.stderr)
        self.assertEqual(health_failures, [])
        self.assertEqual(set(codes) - {"OK", "RESOURCE_EXHAUSTED"}, set(), outcomes)
        self.assertEqual(outcomes, {f"part-{i:02d}": "OK" for i in range(PARTS)})
        self.assertGreater(refused, 0, "twelve 20 M-point streams fit a 2 GB budget at once?")
        self.assertLess(hwm, budget + MARGIN_BYTES)
        with open(self.log_path) as f:
            log = f.read()
        self.assertNotIn("INTERNAL", log)
        self.assertEqual(len(re.findall(r"Inspect from \S+: OK, 20000000 points", log)), PARTS, log[-2000:])


if __name__ == "__main__":
    BIN, SRC = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1] + sys.argv[3:])
