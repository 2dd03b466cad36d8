#!/usr/bin/env bash
# outputs.sh BIN OUT: the demo cell, then filter, calibrate, register, errormap (PLY, CSV, PNG, JSON)
# errormap with the cell's plan (every report file and the printed summary) and inspect
# (in-process and through a surfinspectd it starts), all written under OUT.
# A change keeps every output byte-identical when outputs.sh runs with the binaries from
# before and after it and tests/compare/compare.sh BEFORE AFTER prints "identical".
set -euo pipefail
BIN=$(cd "$1" && pwd); OUT=$2; rm -rf "$OUT"; mkdir -p "$OUT"; cd "$OUT"
si="$BIN/surfinspect"
"$si" demo-cell --out cell --parts 2 >/dev/null
S=cell/scans/part-001
"$si" filter --in $S/v1.pcd --out filtered.pcd --report filter.json --png filter.png >/dev/null
"$si" filter --in $S/v2.pcd --out filtered.ply --link-distance 0.85 --connectivity 4 >/dev/null
python3 - <<'PY'
import json
c = json.load(open('cell/cell.json'))
for v in c['viewpoints']:
    json.dump(v['nominal_world_from_sensor'], open('nominal_%s.json' % v['name'], 'w'))
    json.dump(v['world_from_gauge'], open('wfg_%s.json' % v['name'], 'w'))
json.dump(c['part']['world_from_part'], open('wfp.json','w'))
PY
for v in v1 v2 v3 v4 v5; do
  "$si" calibrate --gauge cell/gauge.stl --world-from-gauge wfg_$v.json --scan cell/gauge_scans/$v.pcd \
    --initial-world-from-sensor nominal_$v.json --out cal_$v.json --report calrep_$v.json >/dev/null
done
args=(); for v in v1 v2 v3 v4 v5; do args+=(--scan $S/$v.pcd --world-from-sensor cal_$v.json); done
"$si" register "${args[@]}" --out merged.ply --filter >/dev/null
"$si" register "${args[@]}" --out merged_raw.ply >/dev/null
"$si" errormap --cloud merged.ply --mesh cell/part.stl --world-from-part wfp.json --out errormap.ply \
  --csv errormap.csv --report errormap.json --png errormap.png --tolerance 0.3 >/dev/null
"$si" errormap --cloud $S/v3.pcd --mesh cell/part.stl --out errormap_v3.ply --csv errormap_v3.csv \
  --png errormap_v3.png --max-distance 5 --threads 1 >/dev/null
# With the cell's plan: the report's characteristics and defects, and every report file.
"$si" errormap --cloud merged.ply --mesh cell/part.stl --world-from-part wfp.json --plan cell/plan.json \
  --out planned.ply --report planned.json --png planned.png --pdf planned.pdf --html planned.html \
  --qif planned.qif >planned.txt
"$BIN/surfinspectd" --listen 127.0.0.1:0 >server.out 2>server.log &
pid=$!; trap 'kill -9 $pid 2>/dev/null' EXIT
for _ in $(seq 100); do grep -q "listening on" server.out 2>/dev/null && break; sleep 0.1; done
T=$(sed -n 's/^surfinspectd listening on //p' server.out)
"$BIN/cell-agent" calibrate --cell cell/cell.json --server "$T" >/dev/null
"$si" inspect --cell cell/cell.json --scans $S --out inspect >/dev/null
"$si" inspect --cell cell/cell.json --scans $S --out inspect_remote --server "$T" >/dev/null
# The unary calls through the server (their requests carry packed clouds).
"$si" filter --in $S/v1.pcd --out filtered_remote.pcd --report filter_remote.json --server "$T" >/dev/null
"$si" calibrate --gauge cell/gauge.stl --world-from-gauge wfg_v2.json --scan cell/gauge_scans/v2.pcd \
  --initial-world-from-sensor nominal_v2.json --out cal_remote_v2.json --server "$T" >/dev/null
"$si" register "${args[@]}" --out merged_remote.ply --filter --server "$T" >/dev/null
"$si" errormap --cloud $S/v3.pcd --mesh cell/part.stl --out errormap_v3_remote.ply \
  --csv errormap_v3_remote.csv --max-distance 5 --server "$T" >/dev/null
rm -f server.out server.log cell/cell.json.bak
