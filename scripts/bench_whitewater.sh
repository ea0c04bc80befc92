#!/usr/bin/env bash
# Whitewater benchmark (issue 33): the whitewater stage's time a frame against the simulation's on the same scene,
# run one after the other in this script (docs/performance.md), and the diffuse particles it carried.
#
#   scripts/bench_whitewater.sh [SURGE_BINARY] [SCENE] [FRAMES]
set -euo pipefail
surge=${1:-build/apps/surge}
scene=${2:-scenes/dam_break.json}
frames=${3:-120}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$surge" sim "$scene" --out "$work" --set output.frames="$frames" --set whitewater.enabled=1 --quiet
"$surge" whitewater "$work" --quiet
# stats.csv's wall_seconds and counts.csv's seconds, summed over frames 1..N.
awk -F, 'FNR == 1 { for (i = 1; i <= NF; ++i) col[FILENAME, $i] = i; next }
  FILENAME ~ /stats.csv$/ { sim += $col[FILENAME, "wall_seconds"]; n++ }
  FILENAME ~ /counts.csv$/ { if ($1 > 0) { white += $col[FILENAME, "seconds"];
    alive = $2 + $3 + $4; total += alive; if (alive > most) most = alive } }
  END { printf "| frames | simulation ms/frame | whitewater ms/frame | share | diffuse particles, mean / most |\n"
        printf "|---|---|---|---|---|\n"
        printf "| %d | %.1f | %.1f | %.0f%% | %.0f / %d |\n", n - 1, 1000 * sim / (n - 1), 1000 * white / (n - 1),
               100 * white / sim, total / (n - 1), most }' "$work/stats.csv" "$work/whitewater/counts.csv"
