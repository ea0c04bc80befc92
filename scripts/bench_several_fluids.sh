#!/usr/bin/env bash
# The cost of several fluids (issue 34): oil_and_water as it ships (oil at 900 kg/m^3 on water) beside the same
# blocks as one fluid (both named water, at 1000), run one after the other in this script, in each method (PBF at
# its 8 steps a frame, 4 iterations and s_corr 0.1 in both; DFSPH and WCSPH at their own steps), so that the time a
# step compares step for step; the share of a step the inverse-mass weighting adds (docs/several-fluids.md). Then
# PBF's two fluids at its defaults for differing densities (at most 30 iterations to 0.1%, no s_corr) against the
# pinned run: what the converged solve costs. Each run three times, the fastest kept (a shared machine).
#
#   scripts/bench_several_fluids.sh [SURGE_BINARY] [FRAMES]
#   METHODS="pbf dfsph" scripts/bench_several_fluids.sh ...   (a subset of the methods)
set -euo pipefail
surge=${1:-build/apps/surge}
frames=${2:-60}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene=scenes/oil_and_water.json
common=(--set output.frames="$frames" --set solver.substeps=8)
source "$(dirname "${BASH_SOURCE[0]}")/bench_steps.sh"
best() {  # best NAME ARGS...: the fastest of three runs' ms a step, and its constraint phase's
  local name=$1
  shift
  fastest_of_three "$surge" "$work/$name" ms_constraint "$scene" "${common[@]}" "$@"
}
echo "| method | one fluid, ms a step | two fluids | ratio | pressure phase, one | two |"
echo "|---|---|---|---|---|---|"
for method in ${METHODS:-pbf dfsph wcsph}; do
  pin=()
  [[ $method == pbf ]] && pin=(--set solver.iterations=4 --set solver.scorr_k=0.1)
  read -r two twoPhase < <(best two --set solver.method="$method" "${pin[@]}")
  read -r one onePhase < <(best one --set solver.method="$method" "${pin[@]}" --set 'fluids[1].name=water' \
    --set 'fluids[1].rest_density=1000' --set 'fluids[1].color=[0.15,0.45,0.8]')
  awk -v m="$method" -v t="$two" -v o="$one" -v tp="$twoPhase" -v op="$onePhase" \
    'BEGIN { printf "| %s | %.2f | %.2f | %.3f | %.2f | %.2f |\n", m, o, t, t / o, op, tp }'
  if [[ $method == pbf ]]; then
    read -r own ownPhase < <(best own --set solver.method=pbf)
    converged=$(awk -v t="$two" -v c="$own" -v cp="$ownPhase" 'BEGIN { printf "PBF, two fluids at its defaults (at '\
'most 30 iterations to 0.1%%, no s_corr): %.2f ms a step, its constraint phase %.2f; %.2f times the run at 4 '\
'iterations", c, cp, c / t }')
  fi
done
[[ -n ${converged:-} ]] && printf '\n%s\n' "$converged"
