#!/usr/bin/env bash
# Two builds of surge side by side on the peer dam break (scripts/bench_peers.sh's: 64,000 particles, 30 frames,
# PBF at 16 steps a frame to a 0.05% density error; DFSPH and WCSPH at their own steps), alternating old and new
# run by run so that the machine's drift falls on both alike. Prints each method's median wall seconds of each
# build and their ratio new / old.
#   scripts/bench_builds.sh OLD_SURGE NEW_SURGE [repeats, default 3]
#   METHODS="pbf dfsph" scripts/bench_builds.sh ...   (a subset of the methods)
set -euo pipefail
old="${1:?usage: bench_builds.sh OLD_SURGE NEW_SURGE [repeats]}"
new="${2:?usage: bench_builds.sh OLD_SURGE NEW_SURGE [repeats]}"
repeats="${3:-3}"
work="out/bench_builds"
mkdir -p "$work"

# The wall seconds of one run.
timed() {  # timed SURGE METHOD
  local start end
  start="$(date +%s.%N)"
  "$1" sim "$(dirname "$0")/../bench/peer_dam_break.json" --quiet --set solver.method="$2" \
    --out "$work/run_$2" >/dev/null
  end="$(date +%s.%N)"
  echo "$end - $start" | bc -l
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), $repeats runs each, alternating"
echo
echo "| method | old (s, median) | new (s, median) | new / old |"
echo "|---|---|---|---|"
for method in ${METHODS:-pbf dfsph wcsph}; do
  : >"$work/$method.old" && : >"$work/$method.new"
  for ((r = 0; r < repeats; ++r)); do
    timed "$old" "$method" >>"$work/$method.old"
    timed "$new" "$method" >>"$work/$method.new"
  done
  a="$(median <"$work/$method.old")" b="$(median <"$work/$method.new")"
  printf "| %s | %.2f | %.2f | %.3f |\n" "$method" "$a" "$b" "$(echo "$b / $a" | bc -l)"
done
