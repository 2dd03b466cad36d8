#!/usr/bin/env python3
"""cell-agent and a real PostgreSQL: two agents for two cells write 20 parts
each into one database at once, nothing lost or doubled; an agent killed
with SIGKILL in the middle of its parts and restarted records every part
exactly once; surfinspect trend reads the result. PostgreSQL 15 runs from
initdb in a temporary folder on a loopback port (as the postgres user when
run as root) and is stopped at the end. Small-sensor cells keep it fast.

usage: agent_store_test.py BIN_DIR
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

BIN = os.path.abspath(sys.argv[1])
PG = "/usr/lib/postgresql/15/bin"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def expect(cond, what):
    if not cond:
        raise AssertionError(what)


class Postgres:
    def __init__(self, root):
        self.dir = os.path.join(root, "pg")
        os.makedirs(os.path.join(self.dir, "sock"))
        self.runner = ["runuser", "-u", "postgres", "--"] if os.geteuid() == 0 else []
        if self.runner:
            subprocess.run(["chown", "-R", "postgres", self.dir], check=True)
        self.port = free_port()
        data = os.path.join(self.dir, "data")
        subprocess.run(self.runner + [f"{PG}/initdb", "-D", data, "-A", "trust", "-U", "postgres",
                                      "--no-sync"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(self.runner + [
            f"{PG}/pg_ctl", "-D", data, "-o",
            f"-p {self.port} -k {self.dir}/sock -c listen_addresses=127.0.0.1 -c fsync=off",
            "-l", os.path.join(self.dir, "log"), "-w", "start"], check=True,
            stdout=subprocess.DEVNULL)
        self.url = f"postgresql://postgres@127.0.0.1:{self.port}/postgres"

    def stop(self):
        subprocess.run(self.runner + [f"{PG}/pg_ctl", "-D", os.path.join(self.dir, "data"), "-m",
                                      "fast", "-w", "stop"], stdout=subprocess.DEVNULL)


def make_cells(root, names):
    """The demo cell at a 128 x 96 sensor, calibrated at the true poses."""
    base = os.path.join(root, "demo")
    subprocess.run([os.path.join(BIN, "surfinspect"), "demo-cell", "--out", base, "--parts", "0"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(base, "cell.json")) as f:
        cell = json.load(f)
    cell["sensor"].update(width=128, height=96)
    for vp in cell["viewpoints"]:
        vp["world_from_sensor"] = vp["simulation_truth_world_from_sensor"]
    cell["filter"] = {"link_distance_mm": 4.0, "min_cluster_points": 20}
    cell["simulation"] = {"stripes": False}
    dirs = {}
    for name in names:
        d = os.path.join(root, name)
        os.makedirs(d)
        for f in ("part.stl", "gauge.stl", "plan.json"):
            shutil.copy(os.path.join(base, f), d)
        # At this pitch (2 mm) the demo's holes are a few pixels across, which
        # surfinspect does not measure: the plan judges the surface only.
        with open(os.path.join(d, "plan.json")) as f:
            plan = json.load(f)
        for key in ("holes", "slots", "edge_points"):
            plan.pop(key, None)
        with open(os.path.join(d, "plan.json"), "w") as f:
            json.dump(plan, f)
        with open(os.path.join(d, "cell.json"), "w") as f:
            json.dump(dict(cell, name=name), f)
        dirs[name] = d
    return dirs


def agent_command(cell_dir, server, db, *extra):
    return [os.path.join(BIN, "cell-agent"), "run", "--cell", os.path.join(cell_dir, "cell.json"),
            "--cell-dir", cell_dir, "--server", server, "--db", db, "--poll", "0.2", *extra]


def agent(cell_dir, server, db, *extra):
    return subprocess.Popen(agent_command(cell_dir, server, db, *extra),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def trend(db, cell, root):
    out = os.path.join(root, f"trend-{cell}.json")
    p = subprocess.run([os.path.join(BIN, "surfinspect"), "trend", "--db", db, "--cell", cell,
                        "--out", os.path.join(root, f"trend-{cell}.html"), "--json", out],
                       capture_output=True, text=True)
    expect(p.returncode == 0, p.stderr)
    with open(out) as f:
        return json.load(f)


def main():
    root = tempfile.mkdtemp(prefix="agent-store-")
    os.chmod(root, 0o755)  # the postgres user walks into it
    pg = server = None
    try:
        pg = Postgres(root)
        cells = make_cells(root, ["cell-a", "cell-b", "cell-k"])
        port = free_port()
        server = subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen",
                                   f"127.0.0.1:{port}", "--threads", "1"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        expect("listening on" in server.stdout.readline(), "surfinspectd did not start")
        target = f"127.0.0.1:{port}"
        t0 = time.time()
        # Two agents, two cells, one database, at once.
        agents = [agent(cells[c], target, pg.url, "--simulate", "20", "--once", "--seed", str(s))
                  for c, s in (("cell-a", 1), ("cell-b", 2))]
        for a in agents:
            out, err = a.communicate(timeout=600)
            expect(a.returncode == 0, f"agent failed:\n{out}\n{err}")
            expect("not recorded" not in err, err)
        for c in ("cell-a", "cell-b"):
            t = trend(pg.url, c, root)
            expect(t["parts"] == 20, f"{c}: {t['parts']} parts")
            expect(len(set(t["part_ids"])) == 20, f"{c}: doubled parts")
        print(f"two agents x 20 parts into PostgreSQL: {time.time() - t0:.1f} s")
        # Killed mid-run, restarted: every part recorded once.
        k = agent(cells["cell-k"], target, pg.url, "--simulate", "12", "--seed", "3")
        results = os.path.join(cells["cell-k"], "results")
        deadline = time.time() + 300
        while time.time() < deadline:
            done = [d for d in os.listdir(results) if os.path.exists(os.path.join(results, d, "report.json"))] if os.path.isdir(results) else []
            if len(done) >= 4:
                break
            time.sleep(0.05)
        k.send_signal(signal.SIGKILL)
        k.wait()
        expect(len(done) < 12, "the agent finished before it was killed")
        k = agent(cells["cell-k"], target, pg.url, "--once")
        out, err = k.communicate(timeout=600)
        expect(k.returncode == 0, f"restarted agent failed:\n{out}\n{err}")
        t = trend(pg.url, "cell-k", root)
        expect(t["parts"] == 12 and len(set(t["part_ids"])) == 12, f"cell-k: {t['part_ids']}")
        print(f"killed after {len(done)} parts, restarted: 12 parts recorded once")
        # The default store: results/results.db beside the parts, no set-up.
        d = agent(cells["cell-a"], target, "", "--once")  # "" = the default
        out, err = d.communicate(timeout=600)
        expect(d.returncode == 0, err)
        t = trend(os.path.join(cells["cell-a"], "results", "results.db"), "cell-a", root)
        expect(t["parts"] == 20, f"SQLite catch-up: {t['parts']}")
        print("ok")
    finally:
        if server:
            server.send_signal(signal.SIGTERM)
            server.wait(timeout=30)
        if pg:
            pg.stop()
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
