#!/usr/bin/env bash
# The cluster test (ctest -L slurm): a private one-node Slurm (scripts/slurm_local.sh) runs a small scene with
# `surge run --slurm` (requeueing one render task while it renders) and a two-point `surge study --slurm`, then
# checks the video, the frames and study.csv, and stops the daemons, leaving nothing running.
# Exits 77 (ctest: skipped, with the reason) when it cannot start Slurm: not root, or slurm-wlm/munge missing.
set -uo pipefail
surge="$1"
source_dir="$2"
work="${3:-${TMPDIR:-/tmp}}/surge_slurm_test_$$"

if [ "$(id -u)" -ne 0 ]; then echo "SKIPPED: the private Slurm runs its daemons as root; this is uid $(id -u)"; exit 77; fi
for program in munged slurmctld slurmd sbatch squeue scontrol; do
  command -v "$program" >/dev/null || { echo "SKIPPED: $program is missing (apt-get install slurm-wlm munge)"; exit 77; }
done

source "$source_dir/scripts/slurm_local.sh"
export SURGE_SLURM_PORT_BASE=$((20000 + ($$ % 4000) * 2))  # two test runs at once do not meet
fail() { echo "FAILED: $*"; exit 1; }
cleanup() {
  slurm_local_stop "$work/slurm"
  if pgrep -f "$work" >/dev/null; then echo "FAILED: processes left running"; pgrep -af "$work"; exit 1; fi
  rm -rf "$work"
}
trap cleanup EXIT
mkdir -p "$work"
slurm_local_start "$work/slurm" || fail "the private Slurm did not start (logs: $work/slurm/log)"

# Waits until none of the jobs is in the queue, at most $2 seconds.
wait_for_jobs() {
  local ids="$1" limit="$2" i
  for i in $(seq 1 $((limit * 5))); do
    [ -z "$(squeue -h -j "$ids" 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  squeue -j "$ids"
  return 1
}

# A tap opening at 0.1 s into an empty tank (frames 0 to 2 hold no particle), about 2,200 particles by frame 29;
# a render of about a second a frame, so that a task can be caught mid-frame.
cat >"$work/scene.json" <<'EOF'
{
  "name": "slurm_small",
  "dimensions": 3,
  "domain": {"min": [0, 0, 0], "max": [0.6, 0.4, 0.3]},
  "particle_spacing": 0.02,
  "emitters": [{"position": [0.15, 0.35, 0.15], "direction": [0, -1, 0], "radius": 0.08, "speed": 1, "start": 0.1}],
  "output": {"fps": 30, "frames": 29},
  "render": {"width": 320, "height": 180, "samples": 48}
}
EOF
out="$work/out"
"$surge" run "$work/scene.json" --slurm --chunk 10 --cpus-per-task 1 --out "$out" || fail "surge run --slurm"
sim=$(awk '$1 == "sim" {print $2}' "$out/slurm/jobs.txt")
render=$(awk '$1 == "render" {print $2}' "$out/slurm/jobs.txt")
ids=$(awk '{print $2}' "$out/slurm/jobs.txt" | paste -sd,)
[ -n "$sim" ] && [ -n "$render" ] || fail "no job ids in $out/slurm/jobs.txt"

# Requeue the first render task seen running once it has written a frame of its chunk and not all ten.
victim=""
for i in $(seq 1 600); do
  for task in $(squeue -h -j "$render" -t R -o '%i' 2>/dev/null); do
    index="${task#*_}"
    done_count=0
    for f in $(seq $((index * 10)) $((index * 10 + 9))); do
      [ -f "$(printf '%s/frames/frame_%05d.png' "$out" "$f")" ] && done_count=$((done_count + 1))
    done
    if [ "$done_count" -ge 1 ] && [ "$done_count" -lt 10 ]; then victim="$task"; break 2; fi
  done
  sleep 0.1
done
[ -n "$victim" ] || fail "no render task was caught between its first and last frame"
sleep 0.4  # into the next frame
scontrol requeue "$victim" || fail "scontrol requeue $victim"
# The frames the task finished before the kill, with their times: the requeued task must leave them.
index="${victim#*_}"
before=$(cd "$out/frames" && for f in $(seq $((index * 10)) $((index * 10 + 9))); do
  name=$(printf 'frame_%05d.png' "$f"); [ -f "$name" ] && stat -c '%n %Y.%y' "$name"; done)
echo "requeued render task $victim after $done_count of its 10 frames"
# Slurm holds a requeued job for two minutes before it may start again; a real cluster waits, the test need not.
for i in $(seq 1 100); do
  squeue -h -j "$victim" -t PD -o '%i' 2>/dev/null | grep -q . && break
  sleep 0.1
done
scontrol update JobId="$victim" StartTime=now || fail "scontrol update $victim StartTime=now"

wait_for_jobs "$ids" 600 || fail "the jobs did not finish within 10 minutes"
restarts=$(scontrol show job "$victim" 2>/dev/null | grep -o 'Restarts=[0-9]*' | head -1)
[ "$restarts" = "Restarts=1" ] || fail "render task $victim was not requeued ($restarts)"
state=$(scontrol show job "$victim" | grep -o 'JobState=[A-Z]*' | head -1)
[ "$state" = "JobState=COMPLETED" ] || fail "render task $victim ended $state"
video_state=$(scontrol show job "$(awk '$1 == "video" {print $2}' "$out/slurm/jobs.txt")" | grep -o 'JobState=[A-Z]*' | head -1)
[ "$video_state" = "JobState=COMPLETED" ] || fail "the video job ended $video_state"

# The requeued task redid only what was missing.
[ -n "$before" ] || fail "no frame of $victim was done before its requeue"
after=$(cd "$out/frames" && echo "$before" | while read -r name rest; do stat -c '%n %Y.%y' "$name"; done)
[ "$before" = "$after" ] || fail "the requeued task rendered again the frames it had finished: $before / $after"

# Every frame, once, and nothing half-written anywhere.
[ "$(ls "$out/particles" | grep -c '^frame_[0-9]*\.ply$')" -eq 30 ] || fail "particle frames: $(ls "$out/particles" | wc -l)"
[ "$(ls "$out/surface" | grep -c '^frame_[0-9]*\.ply$')" -eq 30 ] || fail "surface frames"
[ "$(ls "$out/frames" | grep -c '^frame_[0-9]*\.png$')" -eq 30 ] || fail "rendered frames: $(ls "$out/frames")"
leftovers=$(find "$out" -name '*.tmp*' -o -name '*.partial*')
[ -z "$leftovers" ] || fail "partial files left: $leftovers"
frames=$(ffprobe -v error -select_streams v:0 -count_frames -show_entries stream=nb_read_frames -of csv=p=0 \
  "$out/slurm_small.mp4")
[ "$frames" = "30" ] || fail "the video has $frames frames, not 30"
grep -q "^finished$" "$out/sim_status.txt" || fail "sim_status.txt: $(cat "$out/sim_status.txt")"
# The requeued task's log holds both of its runs (--open-mode=append): the first stopped, the second finished.
log="$out/slurm/logs/render_${render}_${victim#*_}.out"
grep -q "render:" "$log" || fail "the requeued task's log: $(cat "$log")"

# A study: two sweep points as an array, then the report.
cat >"$work/study.json" <<'EOF'
{
  "name": "slurm_study",
  "dimensions": 2,
  "domain": {"min": [0, 0], "max": [0.8, 0.4]},
  "particle_spacing": 0.02,
  "fluids": [{"box": {"min": [0, 0], "max": [0.2, 0.3]}}],
  "output": {"fps": 30, "frames": 6}
}
EOF
"$surge" study "$work/study.json" --sweep solver.iterations=2,4 --slurm --cpus-per-task 1 --out "$work/study" \
  || fail "surge study --slurm"
study_ids=$(awk '{print $2}' "$work/study/slurm/jobs.txt" | paste -sd,)
wait_for_jobs "$study_ids" 300 || fail "the study's jobs did not finish within 5 minutes"
rows=$(tail -n +2 "$work/study/study.csv" | wc -l)
[ "$rows" -eq 2 ] || fail "study.csv has $rows rows: $(cat "$work/study/study.csv")"
grep -c ',ok,' "$work/study/study.csv" | grep -q '^2$' || fail "not every run ok: $(cat "$work/study/study.csv")"
echo "slurm test passed: video of $frames frames, $victim requeued and completed, study of $rows runs"
