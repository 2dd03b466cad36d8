#!/usr/bin/env bash
# compare.sh A B: every file under A equals B, except timing fields in JSON (and the
# "timing" blocks, which also count the queries each search path answered).
cd "$1"; fail=0
for f in $(find . -type f | sort); do
  if [[ $f == *.json ]]; then
    python3 - "$f" "$2/$f" <<'PY' || fail=1
import json,sys
def strip(o):
    if isinstance(o, dict): return {k: strip(v) for k,v in o.items() if k != 'timing' and 'time' not in k and 'seconds' not in k and not k.endswith('_ms') or k in ('rms_ms',)}
    if isinstance(o, list): return [strip(x) for x in o]
    return o
a=strip(json.load(open(sys.argv[1]))); b=strip(json.load(open(sys.argv[2])))
if a!=b: print("DIFF", sys.argv[1]); sys.exit(1)
PY
  else cmp -s "$f" "$2/$f" || { echo "DIFF $f"; fail=1; }; fi
done
echo "compared $(find . -type f | wc -l) files: $([ $fail = 0 ] && echo identical || echo DIFFERENT)"
