#!/usr/bin/env python3
"""report.pdf of a demo part, read back with poppler-utils.

The demo cell with its plan is calibrated through a surfinspectd started here,
then inspected in-process (`surfinspect inspect`, report.pdf next to
report.json; the remote path writes it with the same WritePartOutputs, which
the agent tests run), and its merged cloud is error-mapped with `surfinspect
errormap --pdf` in-process and with --server. For every PDF: pdftotext finds
the part id, the verdict and every characteristic's name and value (as
report.json holds them); pdfinfo says A4; pdffonts lists only embedded fonts;
page 1 rendered by pdftoppm has a coloured (not blank) map area.

usage: pdf_report_test.py BIN_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

BIN = os.path.abspath(sys.argv[1])


def run(*args, cwd):
    subprocess.run([os.path.join(BIN, args[0]), *args[1:]], cwd=cwd, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def tool(*args):
    return subprocess.run(list(args), check=True, capture_output=True, text=True).stdout


def fmt_mm(v):
    return "-" if v is None else "%+.3f" % v


def page_one_ppm(pdf, work):
    """Page 1 at 72 dpi (one pixel per point) as (width, height, rgb bytes)."""
    subprocess.run(["pdftoppm", "-f", "1", "-l", "1", "-r", "72", pdf, os.path.join(work, "pg")],
                   check=True)
    with open(os.path.join(work, "pg-1.ppm"), "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:  # P6 width height maxval, whitespace separated
        while data[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not data[pos:pos + 1].isspace():
            pos += 1
        fields.append(data[start:pos])
    assert fields[0] == b"P6" and fields[3] == b"255", fields
    return int(fields[1]), int(fields[2]), data[pos + 1:]


def hole_texts(c):
    """A hole's row: its name, and when measured its size with the deviation
    and its true position against the zone (core/report/report_content.h)."""
    if c["verdict"] == "not_measured":
        return (c["name"],)
    size, label = ("width", "W") if c["type"] == "slot" else ("diameter", "\u00d8")
    out = [c["name"], "%s %.3f (%s)" % (label, c["measured_%s_mm" % size],
                                         fmt_mm(c["%s_deviation_mm" % size])),
           "TP %.3f / %.3f" % (c["true_position_mm"], c["position_tolerance_mm"])]
    if c["type"] == "slot":
        out.append("L %.3f (%s)" % (c["measured_length_mm"], fmt_mm(c["length_deviation_mm"])))
    return tuple(out)


def check_pdf(pdf, report_json, part_id, work):
    with open(report_json) as f:
        report = json.load(f)
    text = tool("pdftotext", "-raw", pdf, "-")
    flat = "".join(text.split())
    problems = []
    for want in [part_id, "part verdict: " + report["verdict"], report["verdict"].upper()]:
        if "".join(want.split()) not in flat:
            problems.append("missing %r" % want)
    assert report["characteristics"], "the demo plan has characteristics"
    for c in report["characteristics"]:
        value = c["value_mm"] if c["type"] in ("point", "edge_point") else c["mean_mm"]
        wants = (c["name"], fmt_mm(value), fmt_mm(c["min_mm"]), fmt_mm(c["max_mm"]))
        if c["type"] in ("hole", "slot"):
            wants = hole_texts(c)
        elif c["type"] == "edge_point":  # one offset, no min or max
            wants = (c["name"], fmt_mm(value)) if c["verdict"] != "not_measured" else (c["name"],)
        for want in wants:
            if "".join(want.split()) not in flat:
                problems.append("characteristic %s: missing %r" % (c["name"], want))
    info = tool("pdfinfo", pdf)
    if "595.276 x 841.89 pts (A4)" not in info:
        problems.append("not A4: " + info)
    fonts = tool("pdffonts", pdf).splitlines()[2:]
    if not fonts:
        problems.append("no fonts listed")
    for line in fonts:
        if line.split()[-5] != "yes":
            problems.append("font not embedded: " + line)
    w, h, rgb = page_one_ppm(pdf, work)
    coloured = 0
    for y in range(140, 570):
        row = rgb[(y * w + 40) * 3:(y * w + 415) * 3]
        for x in range(0, len(row), 3):
            r, g, b = row[x], row[x + 1], row[x + 2]
            coloured += max(r, g, b) - min(r, g, b) > 60
    share = coloured / (375 * 430)
    if share < 0.03:
        problems.append("map area nearly blank: %.4f coloured" % share)
    print("%s: %d characteristics, %d defects, map %.1f %% coloured, %d bytes" %
          (os.path.relpath(pdf, work), len(report["characteristics"]), len(report["defects"]),
           100 * share, os.path.getsize(pdf)))
    return problems


def main():
    work = tempfile.mkdtemp(prefix="pdf-report-")
    server = None
    problems = []
    try:
        run("surfinspect", "demo-cell", "--out", "cell", "--parts", "1", cwd=work)
        server = subprocess.Popen([os.path.join(BIN, "surfinspectd"), "--listen", "127.0.0.1:0"],
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        target = None
        for line in server.stdout:
            if line.startswith("surfinspectd listening on "):
                target = line.split()[-1]
                break
        assert target, "surfinspectd did not start"
        run("cell-agent", "calibrate", "--cell", "cell/cell.json", "--server", target, cwd=work)
        scans = "cell/scans/part-001"
        run("surfinspect", "inspect", "--cell", "cell/cell.json", "--scans", scans, "--out", "local",
            cwd=work)
        problems += check_pdf(os.path.join(work, "local", "report.pdf"),
                              os.path.join(work, "local", "report.json"), "part-001", work)
        with open(os.path.join(work, "cell", "cell.json")) as f:
            cell = json.load(f)
        with open(os.path.join(work, "wfp.json"), "w") as f:
            json.dump(cell["part"]["world_from_part"], f)
        args = []
        for v in cell["viewpoints"]:
            with open(os.path.join(work, "w_%s.json" % v["name"]), "w") as f:
                json.dump(v["world_from_sensor"], f)
            args += ["--scan", "%s/%s.pcd" % (scans, v["name"]),
                     "--world-from-sensor", "w_%s.json" % v["name"]]
        run("surfinspect", "register", *args, "--out", "merged.ply", "--filter", cwd=work)
        part_id = "p <\"1\"> & 'x'"
        base = ["surfinspect", "errormap", "--cloud", "merged.ply", "--mesh", "cell/part.stl",
                "--world-from-part", "wfp.json", "--plan", "cell/plan.json", "--part-id", part_id]
        run(*base, "--out", "e.ply", "--report", "e.json", "--pdf", "e.pdf", cwd=work)
        run(*base, "--out", "r.ply", "--report", "r.json", "--pdf", "r.pdf", "--server", target,
            cwd=work)
        for name in ("e", "r"):
            problems += check_pdf(os.path.join(work, name + ".pdf"),
                                  os.path.join(work, name + ".json"), part_id, work)
    finally:
        if server:
            server.kill()
            server.wait()
    if problems:
        print("\n".join(problems))
        print("kept for inspection:", work)
        return 1
    shutil.rmtree(work, ignore_errors=True)
    print("report.pdf: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
