#!/usr/bin/env python3
"""surfinspect errormap --db and surfinspect trend, end to end on SQLite:
12 error maps of a sheet whose middle rises 10 um per part are recorded;
trend finds the slope and the spot, writes trend.html/json/png; a part
recorded twice is written once; bad input names the thing; a password is
never printed.

usage: trend_cli_test.py BIN_DIR
"""
import json
import os
import random
import sqlite3
import subprocess
import sys
import tempfile

BIN = os.path.abspath(sys.argv[1])


def cli(*args, cwd, env=None, ok=True):
    p = subprocess.run([os.path.join(BIN, "surfinspect"), *args], cwd=cwd, env=env,
                       capture_output=True, text=True)
    if ok and p.returncode != 0:
        sys.exit(f"FAIL: surfinspect {' '.join(args)}\n{p.stdout}\n{p.stderr}")
    if not ok and p.returncode == 0:
        sys.exit(f"FAIL: surfinspect {' '.join(args)} succeeded\n{p.stdout}")
    return p


def expect(cond, what):
    if not cond:
        sys.exit("FAIL: " + what)


def write_sheet(path):
    # 100 x 50 mm at z = 0, 10 x 5 cells of two triangles.
    verts = [(x * 10.0, y * 10.0, 0.0) for y in range(6) for x in range(11)]
    faces = []
    for y in range(5):
        for x in range(10):
            a = y * 11 + x
            faces += [(a, a + 1, a + 12), (a, a + 12, a + 11)]
    with open(path, "w") as f:
        f.write(f"OFF\n{len(verts)} {len(faces)} 0\n")
        f.writelines(f"{x} {y} {z}\n" for x, y, z in verts)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in faces)


def write_cloud(path, k, rng):
    pts = []
    for i in range(200):
        for j in range(100):
            x, y = 0.25 + i * 0.5, 0.25 + j * 0.5
            bump = 0.010 * k if 40 <= x <= 60 and 20 <= y <= 30 else 0.0
            pts.append((x, y, bump + rng.gauss(0, 0.005)))
    with open(path, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\n"
                "property float x\nproperty float y\nproperty float z\nend_header\n")
        f.writelines(f"{x} {y} {z}\n" for x, y, z in pts)


PLAN = {"schema": "surfinspect.plan/1",
        "points": [{"name": "centre", "position_mm": [50, 25, 0], "normal": [0, 0, 1],
                    "radius_mm": 4, "tolerance_mm": {"lower": -0.1, "upper": 0.1}}],
        "regions": [{"name": "middle", "select": {"box_mm": [[35, 15, -1], [65, 35, 1]]},
                     "tolerance_mm": {"lower": -0.2, "upper": 0.2}}]}


def main():
    work = tempfile.mkdtemp(prefix="trend-cli-")
    rng = random.Random(3)
    write_sheet(os.path.join(work, "sheet.off"))
    with open(os.path.join(work, "plan.json"), "w") as f:
        json.dump(PLAN, f)
    for k in range(12):
        write_cloud(os.path.join(work, f"c{k}.ply"), k, rng)
        p = cli("errormap", "--cloud", f"c{k}.ply", "--mesh", "sheet.off", "--out", f"e{k}.ply",
                "--report", f"r{k}.json", "--plan", "plan.json", "--tolerance", "0.3",
                "--db", "results.db", "--part-id", f"p{k:02d}", "--cell-name", "sheet", cwd=work)
        expect(f"p{k:02d} recorded in results.db" in p.stdout, p.stdout)
    p = cli("errormap", "--cloud", "c3.ply", "--mesh", "sheet.off", "--out", "again.ply",
            "--plan", "plan.json", "--db", "results.db", "--part-id", "p03", "--cell-name", "sheet",
            cwd=work)
    expect("p03 was already recorded" in p.stdout, p.stdout)

    p = cli("trend", "--db", "results.db", "--out", "trend.html", "--json", "trend.json",
            "--png", "trend.png", "--mesh", "sheet.off", cwd=work)
    with open(os.path.join(work, "trend.json")) as f:
        t = json.load(f)
    expect(t["schema"] == "surfinspect.trend/1" and t["parts"] == 12, str(t["parts"]))
    names = [c["name"] for c in t["characteristics"]]
    expect(names == ["surface", "middle", "centre"], str(names))
    centre = t["characteristics"][2]
    expect(abs(centre["slope_mm_per_part"] - 0.010) < 0.0015, str(centre["slope_mm_per_part"]))
    lo, hi = centre["slope_ci_mm_per_part"]
    expect(lo < 0.010 < hi, f"CI {lo} {hi}")
    expect(centre["n"] == 12 and centre["cp"] is not None and centre["violations"], str(centre))
    # The largest mean is on a triangle under the bump (cells x 40..60, y 20..30).
    tri = t["trend_map"]["largest"]["triangle_id"]
    cell_x, cell_y = (tri // 2) % 10, (tri // 2) // 10
    expect(4 <= cell_x <= 5 and cell_y == 2, f"largest mean on triangle {tri}")
    with open(os.path.join(work, "trend.png"), "rb") as f:
        expect(f.read(8) == b"\x89PNG\r\n\x1a\n", "trend.png is a PNG")
    with open(os.path.join(work, "trend.html")) as f:
        html = f.read()
    expect("<svg" in html and '"kind":"trend_map"' in html, "trend.html: charts and the 3D map")
    p = cli("trend", "--db", "results.db", "--out", "plain.html", cwd=work)
    with open(os.path.join(work, "plain.html")) as f:
        plain = f.read()
    expect("<svg" in plain and "<script" not in plain, "trend.html without --mesh: charts only")
    p = cli("trend", "--db", "results.db", "--out", "last.html", "--json", "last.json",
            "--last", "4", "--characteristic", "centre", cwd=work)
    with open(os.path.join(work, "last.json")) as f:
        last = json.load(f)
    expect(last["part_ids"] == ["p08", "p09", "p10", "p11"], str(last["part_ids"]))

    # Bad input, each named.
    def fails(args, needle, env=None):
        p = cli(*args, cwd=work, env=env, ok=False)
        expect(needle in p.stderr, f"{args}: wanted '{needle}' in:\n{p.stderr}")
        return p
    base = ["trend", "--out", "x.html"]
    fails(base + ["--db", "results.db", "--characteristic", "nope"], "unknown characteristic 'nope'")
    fails(base + ["--db", "results.db", "--cell", "nobody"], "no parts match the selection (cell nobody")
    fails(base + ["--db", "missing.db"], "missing.db: no such results database")
    with open(os.path.join(work, "text.db"), "w") as f:
        f.write("not a database\n")
    fails(base + ["--db", "text.db"], "text.db: not an SQLite database")
    con = sqlite3.connect(os.path.join(work, "foreign.db"))
    con.execute("CREATE TABLE invoices (id INTEGER)")
    con.commit()
    con.close()
    fails(base + ["--db", "foreign.db"], "foreign.db: a foreign database")
    con = sqlite3.connect(os.path.join(work, "results.db"))
    con.execute("UPDATE schema_version SET version = 42")
    con.commit()
    con.close()
    fails(base + ["--db", "results.db"], "schema version 42 is newer")
    p = fails(base + ["--db", "postgresql://qa:s3cret@127.0.0.1:1/results"],
              "password on the command line is refused")
    expect("s3cret" not in p.stderr + p.stdout, "password printed")
    env = dict(os.environ, SURFINSPECT_DB="postgresql://qa:s3cret@127.0.0.1:1/results")
    p = fails(["trend", "--out", "x.html"], "postgresql://qa:***@127.0.0.1:1/results", env=env)
    expect("s3cret" not in p.stderr + p.stdout, "password printed")
    print("ok")


if __name__ == "__main__":
    main()
