#!/usr/bin/env python3
"""report.html in a real browser: the demo cell's part is inspected in-process
with the cell's plan (so it has defects), and its report.html is loaded from
file:// in headless Chromium, driven through the DevTools protocol (real
mouse events, Runtime.evaluate). Checks: no console errors; the WebGL canvas
is drawn (most of it is not background, and the palette's colours are on it
and on the legend); a click on a defect row and on a standard-view button
each change the picture; hovering a point shows its deviation; the page's
statistics equal report.json's. Then the same part inspected without its
last two viewpoints: its page draws the CAD area not seen in grey
(switching it off changes the picture) and says so. Prints the screenshots' paths and the time
to interactive.

  html_browser_test.py BIN_DIR WORK_DIR
Exit 77 (a skip, loudly) only when there is no chromium.
"""
import base64
import json
import os
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
import zlib

CHROME_FLAGS = ["--headless=new", "--no-sandbox", "--enable-unsafe-swiftshader",
                "--use-angle=swiftshader", "--allow-file-access-from-files",
                "--window-size=1280,900", "--hide-scrollbars", "--mute-audio",
                "--no-first-run", "--no-default-browser-check"]
BACKGROUND = (0x20, 0x24, 0x2a)  # viewer.js scene background


def fail(msg):
    print("FAIL:", msg, flush=True)
    sys.exit(1)


# --- a small WebSocket client (RFC 6455), enough for the DevTools protocol ---
class WebSocket:
    def __init__(self, url):
        m = re.match(r"ws://([^/:]+):(\d+)(/.*)", url)
        self.sock = socket.create_connection((m.group(1), int(m.group(2))), timeout=60)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET {m.group(3)} HTTP/1.1\r\nHost: {m.group(1)}:{m.group(2)}\r\n"
                           "Upgrade: websocket\r\nConnection: Upgrade\r\n"
                           f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            head += self.sock.recv(1)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise RuntimeError("websocket handshake failed: %r" % head)

    def _exact(self, n):
        buf = bytearray()
        while len(buf) < n:
            chunk = self.sock.recv(n - len(buf))
            if not chunk:
                raise RuntimeError("websocket closed")
            buf += chunk
        return bytes(buf)

    def send(self, text):
        data = text.encode()
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else
                                bytes([0x80 | 126]) + struct.pack(">H", n) if n < 65536 else
                                bytes([0x80 | 127]) + struct.pack(">Q", n))
        self.sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def recv(self):
        message = b""
        while True:
            b0, b1 = self._exact(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._exact(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._exact(8))[0]
            payload = self._exact(n)
            if b0 & 0x0F == 0x8:
                raise RuntimeError("websocket closed by the browser")
            if b0 & 0x0F in (0x9, 0xA):  # ping / pong
                continue
            message += payload
            if b0 & 0x80:
                return message.decode()


class DevTools:
    def __init__(self, ws_url):
        self.ws = WebSocket(ws_url)
        self.next_id = 0
        self.errors = []

    def _event(self, msg):
        method, p = msg.get("method"), msg.get("params", {})
        if method == "Runtime.exceptionThrown":
            d = p["exceptionDetails"]
            self.errors.append("exception: %s %s" % (d.get("text"), d.get("exception", {}).get("description", "")))
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            self.errors.append("console.%s: %s" % (p["type"], [a.get("value", a.get("description")) for a in p.get("args", [])]))
        elif method == "Log.entryAdded" and p["entry"].get("level") == "error":
            self.errors.append("log: %s %s" % (p["entry"].get("text"), p["entry"].get("url", "")))

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.next_id:
                if "error" in msg:
                    raise RuntimeError("%s: %s" % (method, msg["error"]))
                return msg.get("result", {})
            self._event(msg)

    def eval(self, expression):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError("evaluate %s: %s" % (expression, r["exceptionDetails"]))
        return r["result"].get("value")

    def pump(self, seconds):
        """Lets the page run while events are collected."""
        end = time.time() + seconds
        while time.time() < end:
            self.eval("1")
            time.sleep(0.05)

    def settle(self, what, seconds=30):
        """Waits until the viewer has drawn its full point set and has
        nothing pending (viewer.js: state.settled)."""
        end = time.time() + seconds
        while time.time() < end:
            try:
                if self.eval("!!(window.surfinspect && window.surfinspect.settled)"):
                    return
            except RuntimeError:  # the page is still navigating
                pass
            time.sleep(0.05)
        fail("the viewer did not settle in %d s after %s" % (seconds, what))

    def click(self, x, y):
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                      buttons=0 if kind == "mouseReleased" else 1 if kind == "mousePressed" else 0,
                      clickCount=0 if kind == "mouseMoved" else 1)

    def screenshot(self, path, clip=None):
        params = {"format": "png", "captureBeyondViewport": False}
        if clip:
            params["clip"] = dict(clip, scale=1)
        data = base64.b64decode(self.call("Page.captureScreenshot", **params)["data"])
        with open(path, "wb") as f:
            f.write(data)
        return data


# --- PNG decoding with zlib (8-bit RGB or RGBA) ---
def decode_png(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    assert depth == 8 and ctype in (2, 6), (depth, ctype)
    bpp = 3 if ctype == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    prev = bytearray(stride)
    rows = []
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if f == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif f == 2:
            line = bytearray((a + b) & 0xFF for a, b in zip(line, prev))
        elif f == 3:
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 0xFF
        elif f == 4:
            for i in range(stride):
                a = line[i - bpp] if i >= bpp else 0
                b = prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 0xFF
        rows.append(bytes(line))
        prev = line
    return w, h, [[tuple(r[x * bpp:x * bpp + 3]) for x in range(w)] for r in rows]


def pixels(png):
    w, h, rows = decode_png(png)
    return [p for r in rows for p in r]


def near(a, b, tol=3):
    return abs(a[0] - b[0]) <= tol and abs(a[1] - b[1]) <= tol and abs(a[2] - b[2]) <= tol


def rect_of(dt, selector):
    r = dt.eval("(() => { const e = document.querySelector(%s); if (!e) return null;"
                " const b = e.getBoundingClientRect();"
                " return {x: b.x, y: b.y, width: b.width, height: b.height}; })()" % json.dumps(selector))
    if not r:
        fail("no element %s on the page" % selector)
    return r


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        fail("%s failed (%d):\n%s\n%s" % (" ".join(cmd), r.returncode, r.stdout, r.stderr))
    return r.stdout


def calibrate(bin_dir, cell, work):
    """cell-agent calibrate against a surfinspectd started here on loopback."""
    log = open(os.path.join(work, "surfinspectd.log"), "w")
    server = subprocess.Popen([os.path.join(bin_dir, "surfinspectd"), "--listen", "127.0.0.1:0"],
                              stdout=subprocess.PIPE, stderr=log, text=True)
    try:
        target = None
        for line in server.stdout:
            m = re.match(r"surfinspectd listening on (\S+)", line)
            if m:
                target = m.group(1)
                break
        if not target:
            fail("surfinspectd did not start (see %s)" % log.name)
        run([os.path.join(bin_dir, "cell-agent"), "calibrate", "--cell", cell, "--server", target])
    finally:
        server.terminate()
        server.wait(10)
        log.close()


def make_part(bin_dir, work, drop=()):
    """The demo cell's first part inspected; `drop` names viewpoints whose
    scans are left out (a missing viewpoint: the CAD there is not seen)."""
    si = os.path.join(bin_dir, "surfinspect")
    if drop:
        cell = os.path.join(work, "cell", "cell.json")
        scans = sorted(os.listdir(os.path.join(work, "cell", "scans")))[0]
        part = os.path.join(work, "partial", scans)
        os.makedirs(part, exist_ok=True)
        for f in os.listdir(os.path.join(work, "cell", "scans", scans)):
            if os.path.splitext(f)[0] not in drop:
                shutil.copy(os.path.join(work, "cell", "scans", scans, f), part)
        out = os.path.join(work, "results-partial", scans)
        run([si, "inspect", "--cell", cell, "--scans", part, "--out", out])
        return out
    run([si, "demo-cell", "--out", os.path.join(work, "cell"), "--parts", "1"])
    cell = os.path.join(work, "cell", "cell.json")
    calibrate(bin_dir, cell, work)
    scans = sorted(os.listdir(os.path.join(work, "cell", "scans")))[0]
    out = os.path.join(work, "results", scans)
    run([si, "inspect", "--cell", cell, "--scans", os.path.join(work, "cell", "scans", scans),
         "--out", out])
    for f in ("report.html", "report.json"):
        if not os.path.exists(os.path.join(out, f)):
            fail("inspect wrote no " + f)
    return out


def start_chromium(chromium, profile):
    proc = subprocess.Popen([chromium, *CHROME_FLAGS, "--remote-debugging-port=0",
                             "--user-data-dir=" + profile, "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 30
    for line in proc.stderr:
        m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
        if m:
            port = int(m.group(1))
            break
        if time.time() > deadline:
            break
    else:
        proc.kill()
        fail("chromium did not start its DevTools endpoint")
    # Keep draining stderr so chromium never blocks on a full pipe.
    threading.Thread(target=lambda: [None for _ in proc.stderr], daemon=True).start()
    targets = json.load(urllib.request.urlopen("http://127.0.0.1:%d/json/list" % port, timeout=10))
    page = [t for t in targets if t.get("type") == "page"][0]
    return proc, page["webSocketDebuggerUrl"]


def check_drawn(dt, shots, tag):
    canvas = rect_of(dt, "#viewer canvas.gl")
    legend = rect_of(dt, "#legend")
    path = os.path.join(shots, "report_html_%s.png" % tag)
    png = dt.screenshot(path)
    w, h, rows = decode_png(png)
    x0, y0 = int(canvas["x"]) + 1, int(canvas["y"]) + 1
    x1, y1 = int(canvas["x"] + canvas["width"]) - 1, int(canvas["y"] + canvas["height"]) - 1
    lx0, ly0 = int(legend["x"]), int(legend["y"])
    lx1, ly1 = int(legend["x"] + legend["width"]), int(legend["y"] + legend["height"])
    view = [rows[y][x] for y in range(y0, y1, 2) for x in range(x0, x1, 2)
            if not (lx0 - 2 <= x < lx1 + 2 and ly0 - 2 <= y < ly1 + 2)]
    leg = [rows[y][x] for y in range(ly0, ly1) for x in range(lx0, lx1)]
    return path, view, leg


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    bin_dir, work = sys.argv[1], sys.argv[2]
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("SKIPPED (loudly): no chromium on the PATH; report.html was NOT checked in a browser. "
              "Install Debian's chromium (./run deps).", flush=True)
        sys.exit(77)
    started = time.time()
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    shots = os.path.join(work, "screenshots")
    os.makedirs(shots)
    out = make_part(bin_dir, work)
    report = json.load(open(os.path.join(out, "report.json")))
    if not report["defects"]:
        fail("the demo part has no defects to click")
    html = os.path.join(out, "report.html")
    print("report.html: %s (%.1f MB), inspected in %.1f s" %
          (html, os.path.getsize(html) / 1e6, time.time() - started), flush=True)

    profile = tempfile.mkdtemp(prefix="si-chromium-")
    proc, ws = start_chromium(chromium, profile)
    try:
        dt = DevTools(ws)
        for domain in ("Runtime", "Log", "Page"):
            dt.call(domain + ".enable")
        t0 = time.time()
        dt.call("Page.navigate", url="file://" + os.path.abspath(html))
        ready = False
        while time.time() - t0 < 30:
            try:
                ready = dt.eval("!!(window.surfinspect && window.surfinspect.ready)")
            except RuntimeError:
                ready = False
            if ready:
                break
            time.sleep(0.05)
        wall = time.time() - t0
        if not ready:
            fail("the page did not become ready in 30 s; errors: %s" % dt.errors)
        state = dt.eval("window.surfinspect")
        print("time to interactive: %.0f ms (page's own clock from navigation start; goal 3000 ms: "
              "%s); %.2f s wall from Page.navigate; page marks (ms): %s; load average %.1f" %
              (state["tti_ms"], "met" if state["tti_ms"] <= 3000 else "NOT met", wall,
               state["timings"], os.getloadavg()[0]), flush=True)
        # The 3 s goal is reported, not enforced: the machine is shared. Far
        # beyond it something is wrong.
        if state["tti_ms"] > 20000:
            fail("time to interactive %.0f ms" % state["tti_ms"])
        dt.settle("loading")
        state = dt.eval("window.surfinspect")
        dt.eval("window.surfinspect.frame_ms('preview')")  # waits out the frame still queued
        preview_ms = dt.eval("window.surfinspect.frame_ms('preview')")
        full_ms = dt.eval("window.surfinspect.frame_ms('full')")  # last: the screenshots show it
        print("the full set (%d points) was drawn %d ms after the %d-point first frame; "
              "a preview frame takes %.0f ms, a full frame %.0f ms" %
              (state["shown"], state["timings"]["full"] - state["timings"]["rendered"],
               state["preview_points"], preview_ms, full_ms), flush=True)
        dt.pump(0.3)
        checks(dt, shots, report, state)
        check_unseen(dt, shots, make_part(bin_dir, work, drop=("v4", "v5")))
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
        shutil.rmtree(profile, ignore_errors=True)
    print("OK in %.1f s" % (time.time() - started))


def open_page(dt, html):
    """Navigates to `html` and waits until the viewer says it is ready."""
    t0 = time.time()
    dt.call("Page.navigate", url="file://" + os.path.abspath(html))
    while time.time() - t0 < 30:
        try:
            if dt.eval("!!(window.surfinspect && window.surfinspect.ready)"):
                dt.settle("loading " + os.path.basename(html))
                return
        except RuntimeError:
            pass
        time.sleep(0.05)
    fail("%s did not become ready in 30 s; errors: %s" % (html, dt.errors))


def check_unseen(dt, shots, out):
    """The part inspected without its last two viewpoints: its report lists
    the CAD triangles not seen, the page draws them grey (switching them off
    changes the picture) and says how much was seen."""
    report = json.load(open(os.path.join(out, "report.json")))
    coverage = report.get("coverage")
    if not coverage or coverage["surface"] > 0.95 or len(coverage["triangles"]) < 50:
        fail("without two viewpoints the report should list unseen CAD: %s" %
             (coverage and {k: coverage[k] for k in ("surface", "distance_mm")}))
    open_page(dt, os.path.join(out, "report.html"))
    note = dt.eval("document.getElementById('viewer-note').textContent")
    if "grey: CAD not seen" not in note:
        fail("the page does not say what the grey is: %r" % note[:300])
    path1, with_grey, _ = check_drawn(dt, shots, "5_unseen")
    toggle = rect_of(dt, "#unseen-toggle")
    dt.click(toggle["x"] + toggle["width"] / 2, toggle["y"] + toggle["height"] / 2)
    dt.settle("the click on 'not seen'")
    path2, without, _ = check_drawn(dt, shots, "6_unseen_off")
    changed = sum(1 for a, b in zip(with_grey, without) if not near(a, b, 8)) / len(with_grey)
    print("screenshots %s, %s: %.1f%% of the canvas changed when the grey of %d unseen triangles "
          "(%.1f%% of the surface seen) was switched off" %
          (path1, path2, 100 * changed, len(coverage["triangles"]), 100 * coverage["surface"]),
          flush=True)
    if changed < 0.005:
        fail("switching off the unseen CAD area did not change the picture")
    if dt.errors or dt.eval("window.surfinspect.errors"):
        fail("console errors on the partial part's page: %s" % dt.errors)


def checks(dt, shots, report, state):
    palette = dt.eval("JSON.parse(document.getElementById('si-data').textContent).palette")
    colours = [tuple(palette[3 * i:3 * i + 3]) for i in range(255)]
    shown = report["points"]["valid"]
    if not (0 < state["shown"] <= 1_000_000 and state["shown"] <= shown):
        fail("shown points %s (valid %d, cap 1 M)" % (state["shown"], shown))

    # 1. drawn: background share, palette colours on the map and on the legend
    path1, view, leg = check_drawn(dt, shots, "1_iso")
    drawn = sum(1 for p in view if not near(p, BACKGROUND, 6)) / len(view)
    coloured = sum(1 for p in view if any(near(p, c, 3) for c in colours[2:255])) / len(view)
    print("screenshot %s: %.1f%% of the canvas drawn, %.1f%% in palette colours" %
          (path1, 100 * drawn, 100 * coloured), flush=True)
    if drawn < 0.15:
        fail("only %.1f%% of the WebGL canvas differs from the background" % (100 * drawn))
    if coloured < 0.05:
        fail("only %.1f%% of the canvas shows the palette's colours" % (100 * coloured))
    legend_set = set(leg)
    # The legend's ends beyond the range, the range ends, the band centre, grey.
    for index in (1, 2, 85, 86 + 42, 170, 253, 254, 0):
        if not any(near(colours[index], p, 2) for p in legend_set):
            fail("legend lacks palette entry %d %s" % (index, colours[index]))
    band_on_map = sum(1 for p in view if any(near(p, colours[i], 3) for i in range(86, 170)))
    if band_on_map == 0:
        fail("no in-band (green) colour on the map")

    # 2. a click on the first defect row flies the camera there
    row = rect_of(dt, 'tr.defect[data-defect="1"]')
    dt.click(row["x"] + row["width"] / 2, row["y"] + row["height"] / 2)
    dt.settle("the click on defect row 1")
    if not dt.eval("document.querySelector('tr.defect[data-defect=\"1\"]').classList.contains('selected')"):
        fail("the clicked defect row is not selected")
    path2, view2, _ = check_drawn(dt, shots, "2_defect1")
    changed = sum(1 for a, b in zip(view, view2) if not near(a, b, 8)) / len(view)
    print("screenshot %s: %.1f%% of the canvas changed after the click on defect 1" %
          (path2, 100 * changed), flush=True)
    if changed < 0.05:
        fail("the picture did not change after a click on a defect row")
    label = dt.eval("[...document.querySelectorAll('#labels .label')].filter(e => e.style.display !== 'none').map(e => e.textContent)")
    if not any(t.startswith("D1 ") for t in label):
        fail("defect 1's label is not shown after flying there: %s" % label)

    # 3. hovering the point at the centre shows its deviation
    canvas = rect_of(dt, "#viewer canvas.gl")
    cx, cy = canvas["x"] + canvas["width"] / 2, canvas["y"] + canvas["height"] / 2
    dt.call("Input.dispatchMouseEvent", type="mouseMoved", x=cx, y=cy, button="none")
    dt.pump(0.6)
    hover = dt.eval("document.getElementById('hover').hidden ? '' : document.getElementById('hover').textContent")
    print("hover at the defect: %r" % hover, flush=True)
    m = re.match(r"deviation (-?\d+\.\d+) mm at", hover or "")
    if not m:
        fail("hovering the defect shows no deviation: %r" % hover)
    if abs(float(m.group(1))) > max(abs(report["statistics"]["min_mm"]), abs(report["statistics"]["max_mm"])) + 1e-3:
        fail("hover deviation %s outside the report's extremes" % m.group(1))

    # 4. a standard-view button changes the picture again
    top = rect_of(dt, 'button[data-view="top"]')
    dt.click(top["x"] + top["width"] / 2, top["y"] + top["height"] / 2)
    dt.settle("the click on 'top'")
    path3, view3, _ = check_drawn(dt, shots, "3_top")
    changed = sum(1 for a, b in zip(view2, view3) if not near(a, b, 8)) / len(view2)
    print("screenshot %s: %.1f%% of the canvas changed after the 'top' button" % (path3, 100 * changed), flush=True)
    if changed < 0.05:
        fail("the picture did not change after the 'top' view button")

    # 5. the page's statistics are report.json's
    cells = dt.eval("Object.fromEntries([...document.querySelectorAll('#statistics [data-key]')].map(e => [e.dataset.key, e.dataset.value]))")
    want = dict(report["statistics"])
    want.update({k: report["points"][k] for k in ("count", "valid", "matched")})
    want.update({k: report["tolerance"][k] for k in ("within", "above", "below", "fraction_within")})
    for key, value in want.items():
        if key not in cells:
            fail("the page's statistics lack %s" % key)
        if json.loads(cells[key]) != value:
            fail("page %s = %s, report.json %r" % (key, cells[key], value))
    print("statistics: %d values equal report.json's" % len(want), flush=True)
    verdict = dt.eval("document.getElementById('verdict').dataset.verdict")
    if verdict != report["verdict"]:
        fail("banner verdict %s, report %s" % (verdict, report["verdict"]))

    page_errors = dt.eval("window.surfinspect.errors")
    if dt.errors or page_errors:
        fail("console errors: %s %s" % (dt.errors, page_errors))
    print("console: no errors")


if __name__ == "__main__":
    main()
