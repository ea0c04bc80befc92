#!/usr/bin/env bash
# Scale on one machine (docs/performance.md, "Ten million particles"): the default dam break at a spacing that
# gives about 10 million particles, simulated for 3 frames of 1/300 s (4 substeps each, the default for that
# step), then frame 3 surfaced and path-traced. Prints each stage's wall time and peak memory (GNU time), the
# simulator's bytes a particle and seconds a step (from stats.csv).
# Usage: scripts/bench_scale.sh [SPACING]   (0.00262 m: 9.96 million particles; needs about 6 GB)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
surge="$here/build/apps/surge"
spacing="${1:-0.00262}"
out="${SURGE_BENCH_DIR:-$here/out/bench_scale}"
rm -rf "$out"
measure() {  # label, command...: wall seconds and peak resident memory of the command
  local label="$1"
  shift
  /usr/bin/time -f "$label %e s, peak %M KB" -o "$out.time" "$@" >/dev/null
  cat "$out.time"
}
measure sim "$surge" sim "$here/scenes/dam_break.json" --quiet --out "$out" --set particle_spacing="$spacing" \
  --set output.fps=300 --set output.frames=3 --set solver.substeps=0
particles=$(awk -F, 'NR == 2 {print $3}' "$out/stats.csv")
awk -F, -v p="$particles" 'NR == 1 {for (i = 1; i <= NF; ++i) c[$i] = i}
  NR > 2 {s += $c["wall_seconds"]; n += $c["substeps"]}
  END {printf "sim: %d particles, %d steps, %.2f s a step\n", p, n, s / n}' "$out/stats.csv"
peak=$(awk '{print $(NF - 1)}' "$out.time")
awk -v k="$peak" -v p="$particles" 'BEGIN {printf "sim: %.0f bytes a particle at peak (the whole process)\n", k * 1024 / p}'
measure surface "$surge" surface "$out" --frames 3 --quiet
ls -l "$out/surface/frame_00003.ply" "$out/surface/frame_00003.vdb" | awk '{print "surface file:", $NF, $5, "bytes"}'
measure render "$surge" render "$out" --frames 3 --quiet
rm -f "$out.time"
