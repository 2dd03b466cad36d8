#!/usr/bin/env bash
# The end-to-end demo behind `./run demo`: BIN_DIR OUT_DIR.
#  1. write the demo cell (CAD, gauge, viewpoints, simulated gauge scans)
#  2. start surfinspectd on a free loopback port
#  3. cell-agent calibrate (ICP per viewpoint on the service)
#  4. cell-agent run --simulate 3 --once (robot drops 3 parts with dents)
#  5. print the verdicts and where the error maps are
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

say "4. Inspect three simulated parts with planted dents and bumps"
cd "$OUT"
"$BIN/cell-agent" run --cell cell/cell.json --server "$TARGET" --inbox inbox --results results \
  --archive archive --quarantine quarantine --simulate 3 --once

say "5. Error maps"
for d in results/*/; do
  id=$(basename "$d")
  echo "   $id: $OUT/${d}errormap.png  (planted: $(python3 -c "import json;print(', '.join('%+.3f mm r=%.1f' % (-x['depth_mm'], x['radius_mm']) for x in json.load(open('archive/$id/truth.json'))['defects']))" 2>/dev/null || echo see archive))"
done
say "6. Stopping the server"
