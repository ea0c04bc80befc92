# The simulation benchmarks' shared helpers (sourced by scripts/bench_*.sh): a step's time from stats.csv, and
# the fastest of three runs (a shared machine).

# perstep STATS COLUMN: ms a step over frames 1..N (wall_seconds in s, the ms_ columns in ms).
perstep() {
  awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    $1 > 0 { sum += $col[c]; steps += $col["substeps"] }
    END { printf "%.4f", (c == "wall_seconds" ? 1000 : 1) * sum / steps }' "$1"
}

# fastest_of_three SURGE OUT COLUMN SCENE [ARGS...]: `surge sim SCENE ARGS` into OUT three times; prints the
# fastest run's ms a step and its COLUMN's ms a step (a phase).
fastest_of_three() {
  local surge=$1 out=$2 column=$3 fastest="" phase=""
  shift 3
  for run in 1 2 3; do
    "$surge" sim "$@" --out "$out" --quiet
    local step; step=$(perstep "$out/stats.csv" wall_seconds)
    if [ -z "$fastest" ] || awk -v a="$step" -v b="$fastest" 'BEGIN { exit !(a < b) }'; then
      fastest=$step phase=$(perstep "$out/stats.csv" "$column")
    fi
  done
  echo "$fastest $phase"
}
