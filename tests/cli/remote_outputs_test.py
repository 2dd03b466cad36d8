#!/usr/bin/env python3
"""Every CLI step run in-process and with --server writes the same files:
byte for byte, except the wall-clock fields of the JSON reports.

usage: remote_outputs_test.py BIN_DIR
"""
import filecmp
import json
import os
import shutil
import subprocess
import sys
import tempfile

BIN = os.path.abspath(sys.argv[1])
TIMING_KEYS = {"seconds", "timing"}


def run(*args, cwd):
    subprocess.run([os.path.join(BIN, args[0]), *args[1:]], cwd=cwd, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def same_json(a, b):
    # The two runs write into local/ and remote/; paths in reports differ by that.
    with open(a) as fa, open(b) as fb:
        ja = json.loads(fa.read().replace("local/", "OUT/"))
        jb = json.loads(fb.read().replace("remote/", "OUT/"))
    for j in (ja, jb):
        for k in TIMING_KEYS:
            j.pop(k, None)
    return ja == jb


def aligned_cell(work, cell):
    """cell/aligned.json: the demo cell calibrated at the simulator's true
    poses; cell/aligned-plan.json: its plan located by RPS on holes H1 and H4
    and four surface points (docs/alignment.md)."""
    for v in cell["viewpoints"]:
        v["world_from_sensor"] = v["simulation_truth_world_from_sensor"]
    with open(os.path.join(work, "cell", "aligned.json"), "w") as f:
        json.dump(cell, f)
    with open(os.path.join(work, "cell", "plan.json")) as f:
        plan = json.load(f)
    plan["alignment"] = {"mode": "rps", "references": [
        {"name": "A1", "hole": "H1"}, {"name": "A2", "hole": "H4"},
        {"name": "B1", "position_mm": [-70, 15, 59.5]}, {"name": "B2", "position_mm": [110, -15, 59.0]},
        {"name": "C1", "position_mm": [-120, 65, -0.9]}, {"name": "C2", "position_mm": [120, -65, -0.9]}]}
    with open(os.path.join(work, "cell", "aligned-plan.json"), "w") as f:
        json.dump(plan, f)


def main():
    work = tempfile.mkdtemp(prefix="remote-outputs-")
    server = None
    try:
        run("surfinspect", "demo-cell", "--out", "cell", "--parts", "1", cwd=work)
        with open(os.path.join(work, "cell", "cell.json")) as f:
            cell = json.load(f)
        v1 = cell["viewpoints"][0]
        for name, key in (("wfg.json", "world_from_gauge"), ("nominal.json", "nominal_world_from_sensor"),
                          ("truth.json", "simulation_truth_world_from_sensor")):
            with open(os.path.join(work, name), "w") as f:
                json.dump(v1[key], f)
        with open(os.path.join(work, "wfp.json"), "w") as f:
            json.dump(cell["part"]["world_from_part"], f)
        aligned_cell(work, cell)
        server = subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen", "127.0.0.1:0"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        target = server.stdout.readline().strip().rsplit(" ", 1)[-1]
        scan = "cell/scans/part-001/v1.pcd"
        steps = {
            "filter": (["surfinspect", "filter", "--in", scan, "--out", "{d}/f.pcd", "--report", "{d}/f.json",
                        "--png", "{d}/f.png"], ["f.pcd", "f.png"], ["f.json"]),
            "calibrate": (["surfinspect", "calibrate", "--gauge", "cell/gauge.stl", "--world-from-gauge", "wfg.json",
                           "--scan", "cell/gauge_scans/v1.pcd", "--initial-world-from-sensor", "nominal.json",
                           "--out", "{d}/c.json", "--report", "{d}/cq.json"], ["c.json", "cq.json"], []),
            "register": (["surfinspect", "register", "--scan", scan, "--world-from-sensor", "truth.json",
                          "--out", "{d}/merged.ply", "--filter"], ["merged.ply"], []),
            "errormap": (["surfinspect", "errormap", "--cloud", "{d}/merged.ply", "--mesh", "cell/part.stl",
                          "--world-from-part", "wfp.json", "--out", "{d}/e.ply", "--csv", "{d}/e.csv",
                          "--png", "{d}/e.png", "--report", "{d}/e.json", "--tolerance", "0.3"],
                         ["e.ply", "e.csv", "e.png"], ["e.json"]),
            # The demo cell's plan (regions, points, defects) travels typed.
            "errormap --plan": (["surfinspect", "errormap", "--cloud", "{d}/merged.ply", "--mesh", "cell/part.stl",
                                 "--world-from-part", "wfp.json", "--out", "{d}/p.ply", "--png", "{d}/p.png",
                                 "--report", "{d}/p.json", "--tolerance", "0.3", "--plan", "cell/plan.json"],
                                ["p.ply", "p.png"], ["p.json"]),
            # A whole part with an RPS alignment: the plan's block travels
            # typed, the server aligns, and the report says how.
            "inspect --plan (rps)": (["surfinspect", "inspect", "--cell", "cell/aligned.json", "--scans",
                                      "cell/scans/part-001", "--out", "{d}/insp", "--plan", "cell/aligned-plan.json"],
                                     [], ["insp/report.json"]),
        }
        failures = []
        for mode in ("local", "remote"):
            os.makedirs(os.path.join(work, mode))
        for name, (cmd, exact, reports) in steps.items():
            for mode in ("local", "remote"):
                args = [a.replace("{d}", mode) for a in cmd] + (["--server", target] if mode == "remote" else [])
                run(*args, cwd=work)
            for f in exact:
                if not filecmp.cmp(os.path.join(work, "local", f), os.path.join(work, "remote", f), shallow=False):
                    failures.append(f"{name}: {f} differs")
            for f in reports:
                if not same_json(os.path.join(work, "local", f), os.path.join(work, "remote", f)):
                    failures.append(f"{name}: {f} differs beyond timing")
        with open(os.path.join(work, "remote", "insp", "report.json")) as f:
            alignment = json.load(f).get("alignment", {})
        if not alignment.get("aligned"):
            failures.append(f"inspect --plan (rps): not aligned: {alignment}")
        print("\n".join(failures) or f"{len(steps)} steps: identical outputs in-process and via {target}")
        return 1 if failures else 0
    finally:
        if server:
            server.terminate()
            server.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
