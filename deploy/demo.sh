#!/usr/bin/env bash
# The end-to-end demo behind `./run demo`: BIN_DIR OUT_DIR.
#  1. write the demo cell (CAD, gauge, viewpoints, simulated gauge scans)
#  2. start surfinspectd on a free loopback port
#  3. cell-agent calibrate (ICP per viewpoint on the service)
#  4. cell-agent run --simulate 3 --hole-shift 0.4 --once (robot drops 3 parts
#     with dents; the third is made with its first hole 0.4 mm off)
#  5. print per part the verdict, the failed characteristics, the defects
#     found and the planted ones (archive/PART/truth.json)
#  6. stop the server (nothing is left running, even on failure)
set -euo pipefail
BIN=$(cd "${1:?bin dir}" && pwd)
OUT=${2:?output dir}
rm -rf "$OUT"
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
say() { printf '\n\033[1m== %s\033[0m\n' "$*"; }

SERVER_PID=""
cleanup() {
  if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then
    kill -TERM "$SERVER_PID"; wait "$SERVER_PID" 2>/dev/null || true
  fi
}
trap cleanup EXIT

say "1. Demo cell -> $OUT/cell"
"$BIN/surfinspect" demo-cell --out "$OUT/cell" --parts 0
"$BIN/surfinspect" info "$OUT/cell/part.stl" | sed 's/^/   /'

say "2. surfinspectd on a free loopback port"
"$BIN/surfinspectd" --listen 127.0.0.1:0 >"$OUT/server.out" 2>"$OUT/server.log" &
SERVER_PID=$!
for _ in $(seq 100); do grep -q "listening on" "$OUT/server.out" 2>/dev/null && break; sleep 0.1; done
TARGET=$(sed -n 's/^surfinspectd listening on //p' "$OUT/server.out")
[ -n "$TARGET" ] || { cat "$OUT/server.log"; echo "server did not start" >&2; exit 1; }
"$BIN/surfinspect" health --server "$TARGET" | sed "s/^/   $TARGET: /"

say "3. Calibrate the five viewpoints against the gauge"
"$BIN/cell-agent" calibrate --cell "$OUT/cell/cell.json" --server "$TARGET"

say "4. Inspect three simulated parts with planted dents and bumps (the third: a hole 0.4 mm off)"
cd "$OUT"
"$BIN/cell-agent" run --cell cell/cell.json --server "$TARGET" --inbox inbox --results results \
  --archive archive --quarantine quarantine --simulate 3 --hole-shift 0.4 --once

say "5. Results: failed characteristics, defects found and planted"
for d in results/*/; do
  id=$(basename "$d")
  python3 - "$d/report.json" "archive/$id/truth.json" "$OUT/${d}errormap.png" "$id" <<'PY' || echo "   $id: see $OUT/$d"
import json, sys
report, truth_path, png, part = sys.argv[1:]
r = json.load(open(report))
print("   %s: %s  (%s)" % (part, r["verdict"], png))
for c in r["characteristics"]:
    if c["verdict"] != "pass":
        print("     failed %-14s %s" % (c["name"], c["reason"]))
for f in r["defects"]:
    x, y, z = f["centroid_mm"]
    print("     found   #%d %-4s peak %+.3f mm at (%7.1f, %5.1f, %5.1f), %5.1f mm2%s" % (
        f["id"], f["kind"], f["peak_mm"], x, y, z, f["area_mm2"],
        ", " + f["region"] if f["region"] else ""))
try:
    truth = json.load(open(truth_path))
except (OSError, ValueError):
    truth = {}
planted = truth.get("defects", [])
for h in truth.get("holes", []):
    x, y, z = h["cad_position_mm"]
    print("     planted hole at (%7.1f, %5.1f, %5.1f) moved %.2f mm: true position %.2f mm" % (
        x, y, z, sum(v * v for v in h["shift_mm"]) ** 0.5, h["true_position_mm"]))
for p in planted:
    x, y, z = p["center_in_part"]
    print("     planted %-8s %+.3f mm at (%7.1f, %5.1f, %5.1f), r=%.1f mm" % (
        "dent" if p["depth_mm"] > 0 else "bump", -p["depth_mm"], x, y, z, p["radius_mm"]))
PY
done
say "6. Stopping the server"
