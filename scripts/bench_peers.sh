#!/usr/bin/env bash
# Surge beside SPlisHSPlasH on one machine, one run at a time (../shared/peers.md has how to build the peer and
# its two scenes): SPlisHSPlasH's PBF and DFSPH on its own dam break (59,319 particles, 1 s, maxError 0.05%),
# and Surge's PBF and DFSPH on the same block (a 1 x 1 x 1 m block at spacing 0.025, 64,000 particles, in a
# 4 x 3 x 1.5 m tank, 30 frames at 30 fps, max_density_error 0.0005, at most 100 iterations; PBF at 16 steps a
# frame, DFSPH at its CFL step; WCSPH too, at its CFL step on the speed of sound). Runs alternate theirs and
# ours and print one markdown table: wall seconds, CPU seconds, microseconds per particle-step (wall), iterations
# a step, average density error. out/bench_peers/methods.csv has every run's CPU seconds and error, and with
# gnuplot, out/bench_peers/methods_error_vs_cpu.png plots them.
# SPlisHSPlasH's error is its solver's own at exit (the counter of peers.md step 6); Surge's is stats.csv's,
# measured on the positions at each frame's end, the harsher of the two for DFSPH, whose solver predicts.
#   scripts/bench_peers.sh SPH_SIMULATOR PEER_SCENES [build-folder] [repeats]
# PEER_SCENES holds dambreak_pbf.json and dambreak_dfsph.json.
set -euo pipefail
sph="${1:?usage: bench_peers.sh SPH_SIMULATOR PEER_SCENES [build-folder] [repeats]}"
scenes="${2:?usage: bench_peers.sh SPH_SIMULATOR PEER_SCENES [build-folder] [repeats]}"
build="${3:-build}"
repeats="${4:-1}"
surge="$build/apps/surge"
[ -x "$surge" ] || { echo "bench_peers: $surge not found; build first" >&2; exit 2; }
[ -x "$sph" ] || { echo "bench_peers: $sph is not an executable" >&2; exit 2; }
for m in pbf dfsph; do
  [ -f "$scenes/dambreak_$m.json" ] || { echo "bench_peers: $scenes/dambreak_$m.json is missing" >&2; exit 2; }
done

work="out/bench_peers"
mkdir -p "$work"

seconds() {  # the wall time /usr/bin/time -v wrote, in seconds
  sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$1" |
    awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = 60 * s + $i; print s }'
}
cpu() {  # user + system seconds
  awk -F': ' '/User time \(seconds\)|System time \(seconds\)/ { s += $2 } END { print s }' "$1"
}
csv="$work/methods.csv"
echo "run,cpu_seconds,wall_seconds,density_error_avg_percent" >"$csv"
shares="$work/search_shares.txt"
: >"$shares"

peer() {  # peer METHOD LABEL
  local run="$work/sph_$1"
  rm -rf "$run"
  OMP_NUM_THREADS="$(nproc)" /usr/bin/time -v "$sph" --no-gui --output-dir "$(realpath -m "$run")" \
    "$(realpath "$scenes/dambreak_$1.json")" >"$run.out" 2>&1
  local log="$run/log/SPH_log.txt" name="${1^^}"
  awk -v label="$2" -v wall="$(seconds "$run.out")" -v cpu="$(cpu "$run.out")" -v name="$name" -v csv="$csv" '
    /Average number: Time step size:/ { dt = $NF }
    /Total number: Time step size:/ { total = $NF }
    index($0, "Average number: " name " - iterations:") { it = $NF }
    index($0, "Average number: " name " - iterationsV:") { itv = $NF }
    /Average number: avg density error at solver exit/ { err = $NF }
    END {
      steps = total / dt; n = 59319
      iters = itv == "" ? sprintf("%.2f", it) : sprintf("%.2f + %.2f divergence", it, itv)
      printf "| %s | %d | %.0f | %.1f s | %.1f s | %.2f us | %s | %.3f%% |\n", label, n, steps, wall, cpu, 1e6 * wall / (n * steps), iters, err
      printf "%s,%.2f,%.2f,%.4f\n", label, cpu, wall, err >> csv
    }' "$log"
}

ours() {  # ours METHOD LABEL
  local run="$work/surge_$1"
  /usr/bin/time -v "$surge" sim "$(dirname "$0")/../bench/peer_dam_break.json" --quiet --set solver.method="$1" --out "$run" \
    >"$run.out" 2>&1
  awk -F, -v label="$2" -v wall="$(seconds "$run.out")" -v cpu="$(cpu "$run.out")" -v csv="$csv" -v shares="$shares" '
    NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    $1 > 0 {
      n = $col["particles"]; s = $col["substeps"]; steps += s; it += s * $col["iterations"]
      if (col["divergence_iterations"] && $col["divergence_iterations"] != "") itv += s * $col["divergence_iterations"]
      err += $col["density_error_avg"]; frames++
      search += $col["ms_neighbors"] / 1000; simulated += $col["wall_seconds"]
    }
    END {
      iters = itv == 0 ? sprintf("%.2f", it / steps) : sprintf("%.2f + %.2f divergence", it / steps, itv / steps)
      if (it == 0) iters = "none"
      printf "| %s | %d | %d | %.1f s | %.1f s | %.2f us | %s | %.3f%% |\n", label, n, steps, wall, cpu, 1e6 * wall / (n * steps), iters, 100 * err / frames
      printf "%s,%.2f,%.2f,%.4f\n", label, cpu, wall, 100 * err / frames >> csv
      printf "- %s: the neighbour search (sort, reorder, lists) took %.1f s of %.1f s simulating, %.1f%%\n", label, search, simulated, 100 * search / simulated >> shares
    }' "$run/stats.csv"
}

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -n1), load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| run | particles | steps | wall | CPU | per particle-step | iterations a step | average density error |"
echo "|---|---|---|---|---|---|---|---|"
for ((r = 0; r < repeats; ++r)); do
  peer pbf "SPlisHSPlasH PBF"
  ours pbf "Surge PBF"
  peer dfsph "SPlisHSPlasH DFSPH"
  ours dfsph "Surge DFSPH"
done
ours wcsph "Surge WCSPH"
echo
cat "$shares"

if command -v gnuplot >/dev/null; then
  gnuplot -e "csv='$csv'; png='$work/methods_error_vs_cpu.png'" "$(dirname "$0")/plot_methods.gp"
fi
