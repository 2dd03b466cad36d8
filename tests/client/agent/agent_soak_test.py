#!/usr/bin/env python3
"""Soak test of cell-agent and surfinspectd: one long-running agent inspects
hundreds of simulated parts dropped into its inbox in batches, while the
test samples both processes (RSS, open file descriptors, threads) and the
cell folder (temporary files, inbox and results counts) every SAMPLE_S.
After the warm-up (the first WARMUP_FRACTION of the parts) RSS must stay
within RSS_BOUND of its value at the end of the warm-up, descriptors and
threads within FLAT_SPREAD; at the end every part must be in results/ and
archive/ once, with all its files, and once in the SQLite results store,
with nothing left in the inbox or quarantine and no temporary file.
Standard library only.

Small parts: the demo sensor's 1024 x 768 pixels make ~2 M points a part
(seconds each), so after calibration (which reads the demo's full-size gauge
scans from files) cell.json's sensor is shrunk to SENSOR_PX before the parts
are simulated. The pixel pitch grows by the same factor, so the inspection
filter's link distance (LinkClusteringSettings::ForInspection, 0.85 mm at
1024 px) is scaled with it: unscaled, every component falls below the
filter's 50-point class size and the report says "no matched point". The
coarse grid keeps more mixed (stripe) pixels, so the verdicts are noisier
than the demo's; the soak checks bookkeeping and resources, not accuracy
(agent_e2e_test.py does that). A handful of parts is simulated once into a
staging folder and dropped again under new part ids (hard links, DONE last).

usage: agent_soak_test.py BIN_DIR [--parts N] [--csv FILE] [--keep] [unittest args]
  --parts N   parts to inspect (default 200; e.g. 1000 for the long variant)
  --csv FILE  write the time series there
  --keep      keep the work folder (its path is printed)
"""
import argparse
import csv
import json
import math
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
import unittest

BIN = None
PARTS = 200
CSV_PATH = None
KEEP = False

SENSOR_PX = (160, 120)  # width, height: ~20 k points a view, a part well under 0.5 s
DEMO_LINK_MM = 0.85  # LinkClusteringSettings::ForInspection() at the demo's width
STAGED_PARTS = 4  # distinct simulated parts; the soak cycles through them
BATCH = 10  # parts dropped at once, whenever the inbox holds half a batch or less
SAMPLE_S = 0.5
WARMUP_FRACTION = 0.2
RSS_BOUND = 1.10  # max RSS after warm-up over RSS at the end of the warm-up
FLAT_SPREAD = 2  # max - min of descriptors and of threads after warm-up
OUTPUTS = ("report.json", "errormap.ply", "errormap.png", "report.pdf", "report.html",
           "result.qif")
VIEWS = tuple(f"v{i}.pcd" for i in range(1, 6))
COLUMNS = ("seconds", "parts_done", "agent_rss_kb", "agent_fds", "agent_threads",
           "server_rss_kb", "server_fds", "server_threads", "temp_files", "inbox", "results")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(port, log_path):
    """surfinspectd on loopback, one worker thread, its log in log_path."""
    with open(log_path, "a") as log:
        proc = subprocess.Popen(
            [os.path.join(BIN, "surfinspectd"), "--listen", f"127.0.0.1:{port}",
             "--threads", "1", "--max-connection-age", "0"],
            stdout=subprocess.PIPE, stderr=log, text=True)
    line = proc.stdout.readline()
    proc.stdout.close()
    assert "listening on" in line, f"server did not start: {line!r}"
    return proc


def stop(proc, timeout=60):
    """SIGTERM and wait; returns the exit code (None if it was not running)."""
    if proc is None or proc.poll() is not None:
        return None if proc is None else proc.returncode
    proc.send_signal(signal.SIGTERM)
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
        raise


def shrink_sensor(cell_json, width, height):
    """Smaller scans for the parts simulated from now on (see the docstring)."""
    with open(cell_json) as f:
        cell = json.load(f)
    scale = cell["sensor"]["width"] / width
    cell["sensor"].update(width=width, height=height)
    cell["filter"] = {"link_distance_mm": DEMO_LINK_MM * scale}
    with open(cell_json, "w") as f:
        json.dump(cell, f, indent=2)
    drop_edge_features(os.path.join(os.path.dirname(cell_json), cell.get("plan", "plan.json")))


def drop_edge_features(plan_json):
    """At a small sensor's pitch (1.5-2 mm) the demo's 5-12 mm holes are a few
    pixels across, which surfinspect does not measure (core/plan/holes.cpp):
    such a cell's plan judges the surface without holes and edge points."""
    if not os.path.exists(plan_json):
        return
    with open(plan_json) as f:
        plan = json.load(f)
    for key in ("holes", "slots", "edge_points"):
        plan.pop(key, None)
    with open(plan_json, "w") as f:
        json.dump(plan, f, indent=2)


def make_cell(root):
    """A calibrated demo cell in root/cell with a small sensor; returns cell.json."""
    cell = os.path.join(root, "cell")
    subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", cell, "--parts", "0"],
                   check=True, stdout=subprocess.DEVNULL)
    cell_json = os.path.join(cell, "cell.json")
    port = free_port()
    server = start_server(port, os.path.join(root, "server.log"))
    try:
        out = subprocess.run([os.path.join(BIN, "cell-agent"), "calibrate", "--cell", cell_json,
                              "--server", f"127.0.0.1:{port}"],
                             check=True, capture_output=True, text=True).stdout
    finally:
        stop(server)
    assert "calibrated 5 of 5" in out, out
    shrink_sensor(cell_json, *SENSOR_PX)
    return cell_json


def stage_parts(root, cell_json, n, seed):
    """n simulated parts in root/stage (a throwaway run against no server)."""
    stage = os.path.join(root, "stage")
    run = subprocess.run(
        [os.path.join(BIN, "cell-agent"), "run", "--cell", cell_json, "--server", "127.0.0.1:1",
         "--inbox", stage, "--results", os.path.join(root, "throwaway"),
         "--simulate", str(n), "--seed", str(seed), "--once", "--max-attempts", "1",
         "--timeout", "1"], capture_output=True, text=True)
    parts = sorted(os.path.join(stage, p) for p in os.listdir(stage))
    assert len(parts) == n, run.stderr
    return parts


def link_or_copy(src, dst):
    try:
        os.link(src, dst)
    except OSError:
        shutil.copyfile(src, dst)


def drop_part(source, inbox, part_id):
    """source's scans as inbox/part_id; DONE last, as a scanner writes it."""
    dest = os.path.join(inbox, part_id)
    os.makedirs(dest)
    for name in VIEWS:
        link_or_copy(os.path.join(source, name), os.path.join(dest, name))
    open(os.path.join(dest, "DONE"), "w").close()


def proc_sample(pid):
    """(VmRSS kB, open descriptors, threads) of a live process."""
    rss = threads = None
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
            elif line.startswith("Threads:"):
                threads = int(line.split()[1])
    return rss, len(os.listdir(f"/proc/{pid}/fd")), threads


def temporary_files(root):
    """Paths under root left by an unfinished write: names with .tmp- (an
    atomic file write), folders named .partial* and all they hold (a staged
    folder). An empty .partial, the staging root a writer keeps between
    parts, holds no half-written file and is not counted."""
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        rel = os.path.relpath(dirpath, root).split(os.sep)
        inside = any(part.startswith(".partial") for part in rel)
        for name in dirnames + filenames:
            path = os.path.join(dirpath, name)
            if inside or ".tmp-" in name:
                found.append(path)
            elif name.startswith(".partial") and (name != ".partial" or not is_empty(path)):
                found.append(path)
    return found


def is_empty(folder):
    try:
        return not os.listdir(folder)
    except OSError:  # gone since the walk listed it
        return True


def part_folders(path):
    """The part folders in path, sorted; hidden names (a writer's staging
    root) are no parts, as for every reader of these folders."""
    if not os.path.isdir(path):
        return []
    return sorted(e.name for e in os.scandir(path) if e.is_dir() and not e.name.startswith("."))


def count_dirs(path):
    return len(part_folders(path))


class Soak:
    """One agent and one server through n parts, sampled every SAMPLE_S."""

    def __init__(self, root, cell_json, staged, n):
        self.root, self.cell_json, self.staged, self.n = root, cell_json, staged, n
        self.cell = os.path.dirname(cell_json)
        self.dirs = {d: os.path.join(self.cell, d)
                     for d in ("inbox", "results", "archive", "quarantine")}
        os.makedirs(self.dirs["inbox"])
        self.part_ids = [f"soak-{i:05d}" for i in range(1, n + 1)]
        self.dropped = 0
        self.series = []
        self.server = self.agent = None
        self.agent_code = None

    def start(self):
        port = free_port()
        self.server = start_server(port, os.path.join(self.root, "server.log"))
        d = self.dirs
        cmd = [os.path.join(BIN, "cell-agent"), "run", "--cell", self.cell_json,
               "--server", f"127.0.0.1:{port}", "--inbox", d["inbox"], "--results", d["results"],
               "--archive", d["archive"], "--quarantine", d["quarantine"], "--poll", "0.2",
               "--backoff", "0.2", "--backoff-max", "1", "--timeout", "60"]
        with open(os.path.join(self.root, "agent.out"), "w") as out, \
                open(os.path.join(self.root, "agent.err"), "w") as err:
            self.agent = subprocess.Popen(cmd, stdout=out, stderr=err)

    def drop_batch(self):
        for part_id in self.part_ids[self.dropped:self.dropped + BATCH]:
            drop_part(self.staged[self.dropped % len(self.staged)], self.dirs["inbox"], part_id)
            self.dropped += 1

    def sample(self, seconds):
        return (round(seconds, 2), count_dirs(self.dirs["archive"]),
                *proc_sample(self.agent.pid), *proc_sample(self.server.pid),
                len(temporary_files(self.cell)), count_dirs(self.dirs["inbox"]),
                count_dirs(self.dirs["results"]))

    def run(self, deadline_s):
        """Feeds and samples until every part is archived and has its results."""
        t0 = time.monotonic()
        while True:
            tick = time.monotonic()
            for name, proc in (("agent", self.agent), ("server", self.server)):
                if proc.poll() is not None:
                    raise AssertionError(f"{name} exited with {proc.returncode} after "
                                         f"{count_dirs(self.dirs['archive'])} parts")
            if self.dropped < self.n and count_dirs(self.dirs["inbox"]) <= BATCH // 2:
                self.drop_batch()
            self.series.append(self.sample(tick - t0))
            row = dict(zip(COLUMNS, self.series[-1]))
            if row["parts_done"] >= self.n and row["results"] >= self.n and row["inbox"] == 0:
                break
            if tick - t0 > deadline_s:
                done = row["parts_done"]
                raise AssertionError(f"{done} of {self.n} parts after {tick - t0:.0f} s")
            time.sleep(max(0.0, SAMPLE_S - (time.monotonic() - tick)))
        self.agent_code = stop(self.agent)
        stop(self.server)

    def kill(self):
        for proc in (self.agent, self.server):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()


def warmup_end(series, n):
    """Index of the first sample at which the warm-up's parts are done."""
    warm = math.ceil(WARMUP_FRACTION * n)
    return next(i for i, s in enumerate(series) if s[1] >= warm)


def column(rows, name):
    return [r[COLUMNS.index(name)] for r in rows]


def print_summary(series, w, elapsed_s):
    """Start, end of warm-up, max after warm-up and end, one row each."""
    after = series[w:]
    peak = tuple(max(column(after, c)) for c in COLUMNS)
    heads = ("", "t s", "parts", "agent kB", "fds", "thr", "server kB", "fds", "thr",
             "tmp", "inbox", "results")
    rows = (("start", series[0]), ("warm-up end", series[w]), ("max after", peak),
            ("end", series[-1]))
    lines = ["  ".join(f"{h:>11}" for h in heads)]
    lines += [f"{label:>11}" + "".join(f"  {v:>11}" for v in r) for label, r in rows]
    for c in ("agent_fds", "agent_threads", "server_fds", "server_threads"):
        v = column(after, c)
        lines.append(f"after warm-up {c}: {min(v)}..{max(v)}")
    lines.append(f"{len(series)} samples, {elapsed_s:.0f} s in all")
    print("\n" + "\n".join(lines), file=sys.stderr, flush=True)


def write_csv(path, series):
    with open(path, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(COLUMNS)
        out.writerows(series)


class AgentSoakTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        start = time.monotonic()
        cls.root = tempfile.mkdtemp(prefix="agent-soak-")
        if KEEP:
            print(f"work folder {cls.root}", file=sys.stderr)
        else:
            cls.addClassCleanup(shutil.rmtree, cls.root, ignore_errors=True)
        cell_json = make_cell(cls.root)
        staged = stage_parts(cls.root, cell_json, STAGED_PARTS, seed=21)
        cls.soak = Soak(cls.root, cell_json, staged, PARTS)
        cls.addClassCleanup(cls.soak.kill)
        cls.soak.start()
        try:
            cls.soak.run(deadline_s=60 + 2.0 * PARTS)
        finally:  # the series so far also explains a run that failed
            if CSV_PATH:
                write_csv(CSV_PATH, cls.soak.series)
        cls.series = cls.soak.series
        cls.warm = warmup_end(cls.series, PARTS)
        print_summary(cls.series, cls.warm, time.monotonic() - start)

    def test_agent_stops_cleanly_on_sigterm(self):
        self.assertEqual(self.soak.agent_code, 0)

    def test_every_part_has_its_results_once(self):
        results = self.soak.dirs["results"]
        self.assertEqual(part_folders(results), self.soak.part_ids)
        for part_id in self.soak.part_ids:
            for f in OUTPUTS:
                path = os.path.join(results, part_id, f)
                self.assertTrue(os.path.isfile(path), f"{part_id}/{f}")
            with open(os.path.join(results, part_id, "report.json")) as f:
                self.assertIn(json.load(f)["verdict"], ("pass", "fail"), part_id)

    def test_every_part_is_archived_once_and_nothing_is_left(self):
        archive = self.soak.dirs["archive"]
        self.assertEqual(part_folders(archive), self.soak.part_ids)
        for part_id in self.soak.part_ids:
            self.assertEqual(sorted(os.listdir(os.path.join(archive, part_id))),
                             sorted(VIEWS + ("DONE",)), part_id)
        self.assertEqual(part_folders(self.soak.dirs["inbox"]), [])
        self.assertEqual(part_folders(self.soak.dirs["quarantine"]), [])

    def test_every_part_is_reported_once_in_the_agent_log(self):
        with open(os.path.join(self.root, "agent.out")) as f:
            first_words = [line.split()[0] for line in f if line.startswith("soak-")]
        self.assertEqual(sorted(first_words), self.soak.part_ids)

    def test_results_store_has_every_part_once(self):
        db = sqlite3.connect(os.path.join(self.soak.dirs["results"], "results.db"))
        try:
            columns = [row[1] for row in db.execute("PRAGMA table_info(parts)")]
            self.assertIn("part_id", columns)
            ids = [row[0] for row in db.execute("SELECT part_id FROM parts")]
        finally:
            db.close()
        self.assertEqual(sorted(ids), self.soak.part_ids)

    def test_no_temporary_file_is_left(self):
        self.assertEqual(temporary_files(self.soak.cell), [])

    def test_rss_stays_within_bound_after_warmup(self):
        after = self.series[self.warm:]
        for name in ("agent_rss_kb", "server_rss_kb"):
            base = column(self.series, name)[self.warm]
            peak = max(column(after, name))
            self.assertLessEqual(peak, RSS_BOUND * base,
                                 f"{name}: {base} kB at the end of the warm-up, {peak} kB later")

    def test_descriptors_and_threads_are_flat_after_warmup(self):
        after = self.series[self.warm:]
        for name in ("agent_fds", "agent_threads", "server_fds", "server_threads"):
            v = column(after, name)
            self.assertLessEqual(max(v) - min(v), FLAT_SPREAD, f"{name}: {min(v)}..{max(v)}")


def main():
    global BIN, PARTS, CSV_PATH, KEEP
    parser = argparse.ArgumentParser(usage=__doc__.rsplit("usage: ", 1)[1])
    parser.add_argument("bin_dir")
    parser.add_argument("--parts", type=int, default=PARTS)
    parser.add_argument("--csv")
    parser.add_argument("--keep", action="store_true")
    args, rest = parser.parse_known_args()
    BIN, PARTS, CSV_PATH, KEEP = os.path.abspath(args.bin_dir), args.parts, args.csv, args.keep
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
