#!/usr/bin/env bash
# Surface tension's cost (issue 34): the same scene with and without it, one after the other in this script, at
# the same step (solver.time_step, the capillary limit; in WCSPH its own, its sound's), so that the time a step is
# compared step for step; and the share of the step its pass takes (docs/performance.md).
#
#   scripts/bench_surface_tension.sh [SURGE_BINARY] [METHOD] [FRAMES] [DIMENSIONS]   (default 20 frames: before
#   session 58 PBF's drops gained energy by 0.7 s, docs/surface-tension.md; DIMENSIONS 3 runs droplets_zero_g, 2
#   droplets_2d). With surface tension a scene's default support is wider (2.5 spacings in 3D, the method's own
#   in 2D) than without (2): the run without takes the run with's radius, so that their steps compare pass for
#   pass, and a third run times surface tension at 2 spacings.
set -euo pipefail
surge=${1:-build/apps/surge}
method=${2:-dfsph}
frames=${3:-20}
dimensions=${4:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=scenes/droplets_zero_g.json
[ "$dimensions" = 2 ] && scene=scenes/droplets_2d.json
common=(--set output.frames="$frames" --set solver.method="$method" --quiet)
# WCSPH's step is its sound's, some 30 times shorter than the capillary one, and the same with and without.
[ "$method" = wcsph ] || common+=(--set solver.time_step=0.0014 --set solver.substeps=24)
"$surge" sim "$scene" --out "$work/with" "${common[@]}"
radius=$(grep -o '"kernel_radius": [0-9.e-]*' "$work/with/scene.json" | awk '{ print $2 }')
"$surge" sim "$scene" --out "$work/without" "${common[@]}" --set fluids[0].surface_tension=0 \
  --set fluids[1].surface_tension=0 --set fluids[2].surface_tension=0 --set solver.kernel_radius="$radius"
# ms a step from stats.csv over frames 1..N: the whole step (wall_seconds), and the forces phase (ms_viscosity),
# which holds the surface tension pass beside XSPH; and the solver's iterations a step.
source "$(dirname "${BASH_SOURCE[0]}")/bench_steps.sh"
with=$(perstep "$work/with/stats.csv" wall_seconds) without=$(perstep "$work/without/stats.csv" wall_seconds)
pass=$(perstep "$work/with/stats.csv" ms_viscosity) xsph=$(perstep "$work/without/stats.csv" ms_viscosity)
mean() {  # mean STATS COLUMN over frames 1..N (iterations is already a step's mean in each frame)
  awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next } $1 > 0 { sum += $col[c]; n++ }
    END { printf "%.2f", sum / n }' "$1"
}
iw=$(mean "$work/with/stats.csv" iterations) io=$(mean "$work/without/stats.csv" iterations)
awk -v m="$method" -v w="$with" -v o="$without" -v p="$pass" -v x="$xsph" -v iw="$iw" -v io="$io" 'BEGIN {
  printf "| method | ms a step with / without | the pass, ms a step | its share of a step | iterations a step with / without |\n"
  printf "|---|---|---|---|---|\n"
  printf "| %s | %.2f / %.2f | %.2f | %.0f%% | %.1f / %.1f |\n", m, w, o, p - x, 100 * (p - x) / w, iw, io }'
"$surge" sim "$scene" --out "$work/narrow" "${common[@]}" --set solver.kernel_radius=0.002
printf "with surface tension at %s m of support; at 2 spacings: %.2f ms a step, %s iterations a step\n" "$radius" \
  "$(perstep "$work/narrow/stats.csv" wall_seconds)" "$(mean "$work/narrow/stats.csv" iterations)"
