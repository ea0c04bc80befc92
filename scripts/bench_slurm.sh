#!/usr/bin/env bash
# The same scene three ways on one machine, wall time from the command to the finished video (docs/cluster.md):
#   surge run                          everything in one process, all cores
#   surge run --slurm                  the jobs on a private one-node Slurm (scripts/slurm_local.sh)
#   surge run --slurm --stream         the same, the surface tasks starting with the simulation
# Usage (as root): scripts/bench_slurm.sh [SCENE] [--set ...]   default: scenes/dam_break.json, 60 frames.
# Each Slurm task gets one CPU (--cpus-per-task 1), so that with 2 cores the simulation and a surface task can
# run side by side; `surge run` uses both cores for each stage in turn.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
surge="$here/build/apps/surge"
scene="${1:-$here/scenes/dam_break.json}"
shift || true
overrides=("$@")
[ ${#overrides[@]} -gt 0 ] || overrides=(--set output.frames=60)
work="$(mktemp -d /tmp/surge_bench_slurm.XXXXXX)"
source "$here/scripts/slurm_local.sh"
trap 'slurm_local_stop "$work/slurm"; rm -rf "$work"' EXIT
slurm_local_start "$work/slurm"

seconds() { date +%s.%N; }
minus() { awk -v a="$1" -v b="$2" 'BEGIN {print a - b}'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }
wait_for() {  # the job ids of jobs.txt, until none is queued
  local ids
  ids=$(awk '{print $2}' "$1/slurm/jobs.txt" | paste -sd,)
  while [ -n "$(squeue -h -j "$ids" 2>/dev/null)" ]; do sleep 0.2; done
}

start=$(seconds)
"$surge" run "$scene" "${overrides[@]}" --out "$work/local" --quiet
local_time=$(minus "$(seconds)" "$start")

start=$(seconds)
"$surge" run "$scene" "${overrides[@]}" --out "$work/slurm_run" --slurm --cpus-per-task 1 --quiet
wait_for "$work/slurm_run"
slurm_time=$(minus "$(seconds)" "$start")

start=$(seconds)
"$surge" run "$scene" "${overrides[@]}" --out "$work/slurm_stream" --slurm --stream --cpus-per-task 1 --quiet
wait_for "$work/slurm_stream"
stream_time=$(minus "$(seconds)" "$start")

for d in local slurm_run slurm_stream; do
  n=$(ls "$work/$d/frames" | grep -c '\.png$')
  [ -f "$work/$d/"*.mp4 ] || { echo "no video in $d" >&2; exit 1; }
  echo "$d: $n frames"
done
printf 'surge run:                  %6.1f s\n' "$local_time"
printf 'surge run --slurm:          %6.1f s (%s x surge run)\n' "$slurm_time" "$(ratio "$slurm_time" "$local_time")"
printf 'surge run --slurm --stream: %6.1f s (%s x surge run, %s x --slurm)\n' "$stream_time" \
  "$(ratio "$stream_time" "$local_time")" "$(ratio "$stream_time" "$slurm_time")"
