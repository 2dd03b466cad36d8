#!/usr/bin/env bash
# The end-to-end demo behind `./run demo`: BIN_DIR OUT_DIR.
# Each stage prints what it wrote; the first failure stops the demo.
set -euo pipefail
BIN=${1:?bin dir}
OUT=${2:?output dir}
mkdir -p "$OUT"
say() { printf '\n\033[1m== %s\033[0m\n' "$*"; }

say "$("$BIN/surfinspect" --version)"
say "Demo cell: part, gauge, viewpoints and simulated scans -> $OUT/cell"
"$BIN/surfinspect" demo-cell --out "$OUT/cell" --parts 3
say "What the files hold"
"$BIN/surfinspect" info "$OUT/cell/part.stl"
"$BIN/surfinspect" info "$OUT/cell/gauge.stl"
"$BIN/surfinspect" info "$OUT/cell/scans/part-001/v1.pcd"
