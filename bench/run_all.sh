#!/usr/bin/env bash
# Runs the benchmarks: the peer comparison table (peers_bench, which writes
# RESULTS_DIR/latest.md), then each Google Benchmark executable with short
# minimum times, their console output kept in RESULTS_DIR/gbench-*.txt, then
# the stand-alone benches, each kept as RESULTS_DIR/NAME.txt. Every program
# bench/CMakeLists.txt builds is run here.
# Fails loudly on the first error. Budget: < 10 minutes on 2 cores.
#   bench/run_all.sh BIN_DIR RESULTS_DIR
set -euo pipefail
BIN_DIR=${1:?usage: run_all.sh BIN_DIR RESULTS_DIR}
RESULTS_DIR=${2:?usage: run_all.sh BIN_DIR RESULTS_DIR}
mkdir -p "$RESULTS_DIR"
log() { printf '\033[1m[bench]\033[0m %s\n' "$*" >&2; }
die() { printf '\033[31m[bench] error:\033[0m %s\n' "$*" >&2; exit 1; }

[ -x "$BIN_DIR/peers_bench" ] || die "$BIN_DIR/peers_bench not built (SURFINSPECT_BUILD_BENCH=ON)"
[ -x "$BIN_DIR/surfinspectd" ] || die "$BIN_DIR/surfinspectd not built (the service rows need it)"
start=$(date +%s)

log "peer comparison table -> $RESULTS_DIR/latest.md"
"$BIN_DIR/peers_bench" "$RESULTS_DIR" || die "peers_bench failed"

# The per-kernel Google Benchmarks, short: the table above is the record.
# The service rows (ErrorMap over loopback, streaming) live in peers_bench.
if [ "${BENCH_SKIP_GBENCH:-0}" != 1 ]; then
  for b in link_clustering_bench error_map_bench scan_simulator_bench report_bench html_report_bench \
           verify_bench results_store_bench; do
    [ -x "$BIN_DIR/$b" ] || die "$BIN_DIR/$b not built"
    log "$b"
    tmp=$(mktemp "$RESULTS_DIR/.gbench-$b.XXXXXX")
    "$BIN_DIR/$b" --benchmark_min_time=0.2 --benchmark_color=false >"$tmp" || { rm -f "$tmp"; die "$b failed"; }
    mv "$tmp" "$RESULTS_DIR/gbench-$b.txt"
  done
fi
# Stand-alone benches with goals of their own; each prints its table, kept
# as RESULTS_DIR/NAME.txt.
for b in inspection_plan_bench cad_bench; do
  [ -x "$BIN_DIR/$b" ] || die "$BIN_DIR/$b not built"
  log "$b"
  tmp=$(mktemp "$RESULTS_DIR/.$b.XXXXXX")
  "$BIN_DIR/$b" >"$tmp" || { rm -f "$tmp"; die "$b failed"; }
  mv "$tmp" "$RESULTS_DIR/$b.txt"
done
# result.qif and the cell-agent's MQTT listeners against a mosquitto it
# starts on a loopback port, kept as RESULTS_DIR/plant_integration.txt.
[ -x "$BIN_DIR/plant_integration_bench" ] || die "$BIN_DIR/plant_integration_bench not built"
log "plant_integration_bench"
tmp=$(mktemp "$RESULTS_DIR/.plant_integration.XXXXXX")
"$BIN_DIR/plant_integration_bench" >"$tmp" || { rm -f "$tmp"; die "plant_integration_bench failed"; }
mv "$tmp" "$RESULTS_DIR/plant_integration.txt"
# report.html in headless Chromium: time to interactive and frame times.
if command -v chromium >/dev/null; then
  log "report_viewer_bench"
  tmp=$(mktemp "$RESULTS_DIR/.report_viewer.XXXXXX")
  python3 "$(dirname "$0")/report_viewer_bench.py" "$BIN_DIR" "$RESULTS_DIR/.viewer-work" 5 >"$tmp" ||
    { rm -f "$tmp"; die "report_viewer_bench failed"; }
  mv "$tmp" "$RESULTS_DIR/report_viewer.txt"
  rm -rf "$RESULTS_DIR/.viewer-work"
fi
log "done in $(( $(date +%s) - start )) s; table: $RESULTS_DIR/latest.md"
