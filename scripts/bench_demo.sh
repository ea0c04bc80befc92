#!/usr/bin/env bash
# The README demo, timed (issue 15): `surge run scenes/dam_break.json` end to end with the scene's defaults, and
# beside it, in the same script, the same run with the render settings the demo had before the denoiser
# (8 samples a pixel, no filter), and without its whitewater (issue 33), so the times are from one machine on one
# day. Prints each stage's seconds as surge reports them and the whole run's wall time, as a markdown table
# (BENCH_DEMO_RUNS="defaults no_whitewater" runs only those).
#
#   scripts/bench_demo.sh [SURGE_BINARY] [OUT_DIR]
# Defaults: build/apps/surge, out/bench_demo (two run folders under it, left for a look at the videos).
set -euo pipefail
surge=${1:-build/apps/surge}
out=${2:-out/bench_demo}
mkdir -p "$out"

run() {  # name, then --set overrides
  local name=$1
  shift
  local log="$out/$name.log" start end
  rm -rf "${out:?}/$name"
  start=$(date +%s.%N)
  "$surge" run scenes/dam_break.json --out "$out/$name" "$@" >"$log" 2>&1
  end=$(date +%s.%N)
  # The stage summaries, e.g. "render: 163.2 s -> ...": the seconds of each stage.
  local stages
  stages=$(tr '\r' '\n' <"$log" | sed -nE 's/^(sim|surface|render|video): .*in ([0-9.]+) s.*/\2/p; s/^(whitewater|surface|render|video): ([0-9.]+) s.*/\2/p' |
    paste -sd'|' -)
  grep -q '^whitewater:' "$log" || stages=$(echo "$stages" | sed 's/|/|-|/')
  printf '| %s | %s | %.1f |\n' "$name" "$stages" "$(awk "BEGIN { print $end - $start }")"
}

echo "| run | sim s | whitewater s | surface s | render s | video s | wall s |"
echo "|---|---|---|---|---|---|---|"
runs=${BENCH_DEMO_RUNS:-defaults no_whitewater before_denoiser}
for name in $runs; do
  case $name in
    defaults) run defaults ;;
    no_whitewater) run no_whitewater --set whitewater.enabled=0 ;;
    before_denoiser) run before_denoiser --set render.samples=8 --set render.denoise=0 ;;
  esac
done
