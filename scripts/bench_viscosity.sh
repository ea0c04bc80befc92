#!/usr/bin/env bash
# The cost of viscosity and of periodic axes (issue 35), each run beside its baseline in this script, the fastest
# of three runs kept (a shared machine):
# - viscosity: `honey` as it ships (3D, nu = 0.1, implicit, DFSPH, the strain's operator) beside the same scene
#   with nu = 0 and with the component-wise operator, ms a step and the forces phase (stats.csv ms_viscosity:
#   gravity, XSPH and the viscosity) a step;
# - periodic axes: a 3D pool at rest (50 x 20 x 50 particles) periodic along x and z beside the same pool between
#   walls, ms a step, in each method;
# - the transport velocity (solver.background_pressure): Taylor-Green's box (2D, 100 x 100 particles, periodic,
#   a uniform flow, jittered) with p_b = 2e5 Pa (WCSPH), 1e4 Pa (DFSPH, XSPH off) and 4e4 Pa (PBF, XSPH off)
#   beside p_b = 0, ms a step and the phase the push is timed in (the forces; PBF's constraints) a step.
#
#   scripts/bench_viscosity.sh [SURGE_BINARY] [FRAMES] [POOL_FRAMES]   (defaults 30 and 10: WCSPH's pool takes
#   about 5 s a frame)
#   METHODS="pbf dfsph" scripts/bench_viscosity.sh ...   (the methods of the periodic runs)
set -euo pipefail
surge=${1:-build/apps/surge}
frames=${2:-30}
pool_frames=${3:-10}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
source "$(dirname "${BASH_SOURCE[0]}")/bench_steps.sh"
best() {  # best SCENE ARGS...: the fastest of three runs' ms a step, and its forces phase's
  fastest_of_three "$surge" "$work/run" ms_viscosity "$@"
}

echo "| honey | ms a step | forces phase, ms a step |"
echo "|---|---|---|"
read -r with withPhase < <(best scenes/honey.json --set output.frames="$frames")
read -r without withoutPhase < <(best scenes/honey.json --set output.frames="$frames" --set 'fluids[0].viscosity=0')
read -r laplacian laplacianPhase < <(best scenes/honey.json --set output.frames="$frames" \
  --set solver.viscosity_operator=laplacian)
awk -v a="$without" -v b="$with" -v c="$laplacian" -v pa="$withoutPhase" -v pb="$withPhase" -v pc="$laplacianPhase" \
  'BEGIN {
  printf "| nu = 0 | %.3f | %.3f |\n| nu = 0.1, strain | %.3f | %.3f |\n| nu = 0.1, laplacian | %.3f | %.3f |\n",
         a, pa, b, pb, c, pc
  printf "| ratio, strain to nu = 0 | %.3f | viscosity %.0f%% of a step |\n", b / a, 100 * (pb - pa) / b
  printf "| ratio, strain to laplacian | %.3f | %.3f |\n", b / c, pb / pc }'

cat >"$work/pool.json" <<'JSON'
{"name": "pool", "dimensions": 3, "domain": {"min": [0, 0, 0], "max": [0.5, 0.3, 0.5]},
 "particle_spacing": 0.01, "fluids": [{"box": {"min": [0, 0, 0], "max": [0.5, 0.2, 0.5]}}],
 "output": {"fps": 30, "frames": 30}}
JSON
echo
echo "| pool at rest | walls, ms a step | periodic x and z | ratio |"
echo "|---|---|---|---|"
for method in ${METHODS:-pbf dfsph wcsph}; do
  read -r walled _ < <(best "$work/pool.json" --set output.frames="$pool_frames" --set solver.method="$method")
  read -r periodic _ < <(best "$work/pool.json" --set output.frames="$pool_frames" --set solver.method="$method" \
    --set 'domain.periodic=["x","z"]')
  awk -v m="$method" -v a="$walled" -v b="$periodic" 'BEGIN { printf "| %s | %.3f | %.3f | %.3f |\n", m, a, b, b / a }'
done

cat >"$work/box.json" <<'JSON'
{"name": "box", "dimensions": 2, "domain": {"min": [0, 0], "max": [1, 1], "periodic": ["x", "y"]},
 "particle_spacing": 0.01, "gravity": [0, 0],
 "fluids": [{"box": {"min": [0, 0], "max": [1, 1]}, "velocity": [1, 0.5], "jitter": 0.2, "viscosity": 0.01}],
 "solver": {"method": "wcsph", "speed_of_sound": 10, "kernel": "wendland_c2", "kernel_radius": 0.035},
 "output": {"fps": 30, "frames": 30}}
JSON
# box_table METHOD SCENE P_B PHASE_COLUMN: the box without and with the push, ms a step and the phase the push
# is timed in (stats.csv's column).
box_table() {
  local method=$1 scene=$2 pb=$3 column=$4 plain plainPhase pushed pushedPhase
  echo
  echo "| Taylor-Green's box, $method | ms a step | $column, ms a step |"
  echo "|---|---|---|"
  read -r plain plainPhase < <(fastest_of_three "$surge" "$work/run" "$column" "$scene" --set output.frames="$pool_frames")
  read -r pushed pushedPhase < <(fastest_of_three "$surge" "$work/run" "$column" "$scene" \
    --set output.frames="$pool_frames" --set solver.background_pressure="$pb")
  awk -v a="$plain" -v b="$pushed" -v pa="$plainPhase" -v pb="$pushedPhase" -v p="$pb" 'BEGIN {
    printf "| p_b = 0 | %.3f | %.3f |\n| p_b = %s Pa | %.3f | %.3f |\n| ratio | %.3f | transport velocity %.0f%% of a step |\n",
           a, pa, p, b, pb, b / a, 100 * (b - a) / b }'
}
box_table WCSPH "$work/box.json" 2e5 ms_viscosity
sed 's/"method": "wcsph", "speed_of_sound": 10,/"method": "dfsph", "xsph_c": 0,/' "$work/box.json" >"$work/box_dfsph.json"
box_table DFSPH "$work/box_dfsph.json" 1e4 ms_viscosity
# PBF with its own kernels at 3 spacings; its push is timed with the constraints.
sed 's/"method": "wcsph", "speed_of_sound": 10, "kernel": "wendland_c2", "kernel_radius": 0.035/"method": "pbf", "xsph_c": 0, "kernel_radius": 0.03/' \
  "$work/box.json" >"$work/box_pbf.json"
box_table PBF "$work/box_pbf.json" 4e4 ms_constraint
