#!/usr/bin/env python3
"""report.html in headless Chromium (software WebGL, as in the test): the
demo cell's inspected part is loaded LOADS times, each in a fresh browser,
and the medians of the page's own marks are printed: time to interactive
(the first frame complete, a prefix of the points), the first frame of the
full set, and the cost of a preview and of a full frame once warm.

  report_viewer_bench.py BIN_DIR WORK_DIR [LOADS]   (default 5 loads)
"""
import os
import shutil
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "report"))
import html_browser_test as browser  # noqa: E402  (the DevTools client and the demo part)


def load_once(chromium, html):
    profile = tempfile.mkdtemp(prefix="si-bench-")
    proc, ws = browser.start_chromium(chromium, profile)
    try:
        dt = browser.DevTools(ws)
        for domain in ("Runtime", "Page"):
            dt.call(domain + ".enable")
        dt.call("Page.navigate", url="file://" + html)
        dt.settle("loading", seconds=60)
        s = dt.eval("window.surfinspect")
        dt.eval("window.surfinspect.frame_ms('preview')")  # waits out the queued frame
        preview = statistics.median(dt.eval("window.surfinspect.frame_ms('preview')") for _ in range(3))
        full = statistics.median(dt.eval("window.surfinspect.frame_ms('full')") for _ in range(3))
        return s["tti_ms"], s["timings"]["full"], preview, full, s["shown"], s["preview_points"]
    finally:
        proc.terminate()
        proc.wait(10)
        shutil.rmtree(profile, ignore_errors=True)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    bin_dir, work = sys.argv[1], os.path.abspath(sys.argv[2])
    loads = int(sys.argv[3]) if len(sys.argv) == 4 else 5
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        sys.exit("report_viewer_bench: no chromium on the PATH (./run deps installs it)")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    html = os.path.join(browser.make_part(bin_dir, work), "report.html")
    rows = [load_once(chromium, html) for _ in range(loads)]
    med = [statistics.median(r[i] for r in rows) for i in range(4)]
    print("report.html %.1f MB: %d points shown, first frame %d (median of %d fresh loads, "
          "load average %.1f)" % (os.path.getsize(html) / 1e6, rows[0][4], rows[0][5], loads,
                                  os.getloadavg()[0]))
    print("  time to interactive   %6.0f ms   (goal <= 3000; each load: %s)" %
          (med[0], " ".join("%.0f" % r[0] for r in rows)))
    print("  full set first drawn  %6.0f ms" % med[1])
    print("  preview frame         %6.0f ms" % med[2])
    print("  full frame            %6.0f ms" % med[3])


if __name__ == "__main__":
    started = time.time()
    main()
    print("  (bench took %.0f s)" % (time.time() - started))
