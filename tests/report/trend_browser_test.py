#!/usr/bin/env python3
"""trend.html's 3D trend map in a real browser: 8 error maps of a sheet whose
middle rises 10 um per part (and with a patch of random error) are recorded
in SQLite (surfinspect errormap --db), `surfinspect trend --mesh` writes
trend.html, and headless Chromium loads it from file://. Checks: no console
errors; the map is drawn; the pointer over the trend map's largest triangle
(from trend.json) shows that triangle and its mean; every 7th triangle is
drawn in the palette colour of its mean from trend.json, and after the
switch to sigma in that of its sigma; the random patch changes colour with
the switch; the page has every characteristic.

  trend_browser_test.py BIN_DIR WORK_DIR
Exit 77 (a skip, loudly) only when there is no chromium.
"""
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "cli"))
import trend_cli_test as sheet  # noqa: E402  (the sheet, its clouds and plan)
import html_browser_test as browser  # noqa: E402  (DevTools, PNG decoding)

BIN = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else ""


def fail(msg):
    print("FAIL:", msg, flush=True)
    sys.exit(1)


def run(*args, cwd):
    p = subprocess.run([os.path.join(BIN, "surfinspect"), *args], cwd=cwd, capture_output=True, text=True)
    if p.returncode != 0:
        fail("surfinspect %s:\n%s%s" % (" ".join(args), p.stdout, p.stderr))


def write_cloud(path, k, rng):
    """trend_cli_test's sheet, its middle rising 10 um a part (systematic),
    plus a patch at x 70..90, y 10..20 that jumps by +-30 um from part to
    part (random: a mean near 0, a large sigma)."""
    jump = rng.choice((-0.03, 0.03))
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 20000\n"
                "property float x\nproperty float y\nproperty float z\nend_header\n")
        for i in range(200):
            for j in range(100):
                x, y = 0.25 + i * 0.5, 0.25 + j * 0.5
                z = rng.gauss(0, 0.005)
                z += 0.010 * k if 40 <= x <= 60 and 20 <= y <= 30 else 0.0
                z += jump if 70 <= x <= 90 and 10 <= y <= 20 else 0.0
                f.write("%.5f %.5f %.5f\n" % (x, y, z))


def make_trend(work):
    rng = random.Random(5)
    sheet.write_sheet(os.path.join(work, "sheet.off"))
    with open(os.path.join(work, "plan.json"), "w") as f:
        json.dump(sheet.PLAN, f)
    for k in range(8):
        write_cloud(os.path.join(work, "c%d.ply" % k), k, rng)
        run("errormap", "--cloud", "c%d.ply" % k, "--mesh", "sheet.off", "--out", "e%d.ply" % k,
            "--plan", "plan.json", "--tolerance", "0.3", "--db", "results.db", "--part-id",
            "p%02d" % k, "--cell-name", "sheet", cwd=work)
    run("trend", "--db", "results.db", "--mesh", "sheet.off", "--out", "trend.html", "--json",
        "trend.json", cwd=work)
    with open(os.path.join(work, "trend.json")) as f:
        return json.load(f)


def centroid(triangle):
    """The centre of sheet.off's triangle (trend_cli_test.write_sheet's layout)."""
    cell, upper = divmod(triangle, 2)
    y, x = divmod(cell, 10)
    a = (x * 10.0, y * 10.0)
    b, c = ((a[0] + 10, a[1] + 10), (a[0], a[1] + 10)) if upper else ((a[0] + 10, a[1]), (a[0] + 10, a[1] + 10))
    return [(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, 0.0]


def palette_index(d, tol, rng):
    """core/report/deviation_palette.h's layout: 0 no value, 1 / 254 beyond
    the range, runs of 84 below, inside and above the band."""
    if d is None or d != d:
        return 0
    clamp = lambda f: min(83, max(0, int(f * 84 // 1)))  # noqa: E731
    if abs(d) <= tol:
        return 86 + clamp((d / tol + 1) / 2)
    s = (abs(d) - tol) / (rng - tol) if rng > tol else 1
    if s > 1:
        return 254 if d > 0 else 1
    return 170 + clamp(s) if d > 0 else 2 + 83 - clamp(s)


def check_colours(dt, rows, colours, trend, mode):
    """The pixel at each triangle's centre has its palette colour in `mode`."""
    scale = dt.eval("(() => { const T = JSON.parse(document.getElementById('si-data').textContent).trend;"
                    " return [T.%s_band_mm, T.%s_range_mm]; })()" % (mode, mode))
    column = {"mean": 2, "sigma": 3}[mode]
    checked = 0
    for t in trend["trend_map"]["triangles"][::7] + [[trend["trend_map"]["largest"]["triangle_id"]]]:
        t = trend["trend_map"]["triangles"][t[0]]
        x, y = dt.eval("window.surfinspect.project(%s)" % json.dumps(centroid(t[0])))
        px = rows[int(y)][int(x)]
        want = palette_index(t[column], *scale)
        ok = [i for i in (want - 1, want, want + 1) if 0 <= i < 255 and (i - 2) // 84 == (want - 2) // 84]
        if not any(browser.near(px, colours[i], 3) for i in ok):
            fail("%s: triangle %d (%.5f mm) is drawn %s, its palette colour is %s (index %d)" %
                 (mode, t[0], t[column], px, colours[want], want))
        checked += 1
    return checked


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("SKIPPED (loudly): no chromium on the PATH; trend.html was NOT checked in a browser.")
        sys.exit(77)
    work = sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    trend = make_trend(work)
    largest = trend["trend_map"]["largest"]
    profile = tempfile.mkdtemp(prefix="si-chromium-")
    proc, ws = browser.start_chromium(chromium, profile)
    try:
        dt = browser.DevTools(ws)
        for domain in ("Runtime", "Log", "Page"):
            dt.call(domain + ".enable")
        dt.call("Page.navigate", url="file://" + os.path.abspath(os.path.join(work, "trend.html")))
        dt.settle("loading")
        checks(dt, work, trend, largest)
    finally:
        proc.terminate()
        proc.wait(10)
        shutil.rmtree(profile, ignore_errors=True)


def hover(dt, point):
    x, y = dt.eval("window.surfinspect.project(%s)" % json.dumps(point))
    dt.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y, button="none")
    dt.pump(0.4)
    text = dt.eval("document.getElementById('hover').hidden ? '' : document.getElementById('hover').textContent")
    return (x, y), text


def checks(dt, work, trend, largest):
    palette = dt.eval("JSON.parse(document.getElementById('si-data').textContent).palette")
    colours = [tuple(palette[3 * i:3 * i + 3]) for i in range(255)]
    shot = os.path.join(work, "trend_1_mean.png")
    w, h, rows = browser.decode_png(dt.screenshot(shot))
    canvas = browser.rect_of(dt, "#viewer canvas.gl")
    view = [rows[y][x] for y in range(int(canvas["y"]) + 1, int(canvas["y"] + canvas["height"]) - 1, 3)
            for x in range(int(canvas["x"]) + 1, int(canvas["x"] + canvas["width"]) - 140, 3)]
    drawn = sum(1 for p in view if not browser.near(p, browser.BACKGROUND, 6)) / len(view)
    print("screenshot %s: %.1f%% of the canvas drawn" % (shot, 100 * drawn), flush=True)
    if drawn < 0.1:
        fail("only %.1f%% of the canvas is drawn" % (100 * drawn))

    (x, y), text = hover(dt, centroid(largest["triangle_id"]))
    print("pointer on the largest triangle %d: %r" % (largest["triangle_id"], text), flush=True)
    m = re.match(r"triangle (\d+): mean (-?\d+\.\d+) mm, sigma (\d+\.\d+) mm over (\d+) parts", text or "")
    if not m or int(m.group(1)) != largest["triangle_id"]:
        fail("hover over triangle %d shows %r" % (largest["triangle_id"], text))
    if abs(float(m.group(2)) - largest["mean_mm"]) > 6e-5:
        fail("hover mean %s, trend.json %s" % (m.group(2), largest["mean_mm"]))
    # Re-shoot with the pointer there: the largest mean is above the band, a corner is in it.
    rows = browser.decode_png(dt.screenshot(shot))[2]
    px = rows[int(y)][int(x)]
    if not any(browser.near(px, colours[i], 3) for i in range(170, 255)):
        fail("the largest triangle is drawn %s, not in the above-band colours" % (px,))
    cx, cy = dt.eval("window.surfinspect.project(%s)" % json.dumps(centroid(0)))
    corner = rows[int(cy)][int(cx)]
    if not any(browser.near(corner, colours[i], 3) for i in range(86, 170)):
        fail("a flat corner triangle is drawn %s, not in the band's colours" % (corner,))
    print("colours: largest triangle %s (above the band), corner %s (in the band)" % (px, corner))

    n = check_colours(dt, rows, colours, trend, "mean")
    print("mean: %d triangles drawn in their palette colours" % n)

    radio = browser.rect_of(dt, 'input[name="trend-mode"][value="sigma"]')
    dt.click(radio["x"] + radio["width"] / 2, radio["y"] + radio["height"] / 2)
    dt.settle("switching to sigma")
    if dt.eval("window.surfinspect.mode") != "sigma":
        fail("the sigma switch did not switch")
    shot2 = os.path.join(work, "trend_2_sigma.png")
    rows2 = browser.decode_png(dt.screenshot(shot2))[2]
    n = check_colours(dt, rows2, colours, trend, "sigma")
    print("screenshot %s: sigma: %d triangles drawn in their palette colours" % (shot2, n))
    # The random patch (cell x 7..8, y 1): near 0 in the mean, high in sigma.
    patch = [t for t in trend["trend_map"]["triangles"] if t[0] in (34, 35, 36, 37)]
    means, sigmas = [abs(t[2]) for t in patch], [t[3] for t in patch]
    if not (max(means) < 0.3 * trend["trend_map"]["largest"]["mean_mm"] and min(sigmas) > 0.01):
        fail("the random patch: means %s, sigmas %s" % (means, sigmas))
    for t in patch:
        x, y = dt.eval("window.surfinspect.project(%s)" % json.dumps(centroid(t[0])))
        before, after = rows[int(y)][int(x)], rows2[int(y)][int(x)]
        if browser.near(before, after, 20):
            fail("triangle %d: %s in the mean and %s in sigma" % (t[0], before, after))
    print("the random patch: mean near 0 (%s), sigma high (%s); its colour changed" %
          (before, after))

    names = dt.eval("[...document.querySelectorAll('#side h2')].map(e => e.firstChild.textContent.trim())")
    want = [c["name"] for c in trend["characteristics"]]
    if names != want:
        fail("the page's characteristics %s, trend.json's %s" % (names, want))
    errors = dt.eval("window.surfinspect.errors")
    if dt.errors or errors:
        fail("console errors: %s %s" % (dt.errors, errors))
    print("characteristics %s; console: no errors; ok" % names)


if __name__ == "__main__":
    main()
