#!/usr/bin/env bash
# Simulator benchmark table (docs/performance.md, "Simulator"): runs bench/surge_bench_sim and prints, against
# the goals of the PBF issue, particle-iterations per second per core (3D dam break, 4 substeps, 4 iterations),
# bytes per particle at peak, and the 1M-particle grid rebuild spread out and piled in a corner, the piled
# case as a ratio to the spread one measured in the same run.
#   scripts/bench_sim.sh [build-folder]
set -euo pipefail
build="${1:-build}"
bench="$build/bench/surge_bench_sim"
[ -x "$bench" ] || { echo "bench_sim: $bench not found; build with -DSURGE_BUILD_BENCHMARKS=ON" >&2; exit 2; }

csv="$(mktemp)"
trap 'rm -f "$csv"' EXIT
# One run per group: the CSV reporter wants the same counters on every row.
for group in PbfDamBreak GridRebuild NeighborLists; do
  "$bench" --benchmark_format=csv --benchmark_min_time=2 --benchmark_filter="$group" 2>/dev/null | sed '1!b; /^name/!d' >>"$csv"
done

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p' | head -n1), load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
awk -F, '
  function counter(name,   i) { for (i = 1; i <= NF; ++i) if (header[i] == name) return $i; return "" }
  /^name,/ { delete header; for (i = 1; i <= NF; ++i) { header[i] = $i; gsub(/"/, "", header[i]) } next }
  {
    name = $1; gsub(/"/, "", name)
    wall = $3 + 0; cpu = $4 + 0
    if (name ~ /PbfDamBreak/) {
      n = counter("particles"); rate = counter("particle_iterations/s"); bytes = counter("bytes_per_particle")
      solver = counter("solver_bytes_per_particle")
      split(name, parts, "/"); threads = parts[3]; sub("threads:", "", threads)
      printf "| PBF dam break, %.0fk particles, %s thread(s) | %.2f M/s per core | >= 3 M/s per core | %.0f B held, %.0f B peak RSS | <= 400 B |\n", \
        n / 1000, threads, rate / 1e6, solver, bytes
    } else if (name ~ /GridRebuild/) {
      if (name ~ /piled:1/) piled = wall; else spread = wall
    } else if (name ~ /NeighborLists\/piled:0\/cells_per_radius:1/) { listsSpread = wall
    } else if (name ~ /NeighborLists\/piled:1\/cells_per_radius:1/) { listsPiled = wall
    } else if (name ~ /NeighborLists\/piled:0\/cells_per_radius:2/) { listsFine = wall }
  }
  END {
    printf "| grid rebuild (sort + reorder), 1M spread | %.1f ms | < 100 ms | | |\n", spread
    printf "| grid rebuild, 1M piled in a corner of a 512x larger tank | %.1f ms (%.2fx spread) | no slower | | |\n", piled, piled / spread
    printf "| neighbour lists, 1M spread, cells of h | %.0f ms (cells of h/2: %.2fx) | | | |\n", listsSpread, listsFine / listsSpread
    printf "| neighbour lists, 1M piled | %.0f ms (%.2fx spread) | | | |\n", listsPiled, listsPiled / listsSpread
  }' "$csv" | { echo "| measure | measured | goal | bytes/particle | goal |"; echo "|---|---|---|---|---|"; cat; }
