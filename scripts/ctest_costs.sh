#!/usr/bin/env bash
# Writes tests/ctest_costs.txt from a build folder's ctest record (default build/): the tests over 10 s, so that
# `scripts/setup.sh test` in a fresh clone starts them first (ctest orders by these costs at -j 2 and more).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
record="${1:-build}/Testing/Temporary/CTestCostData.txt"
[ -f "$record" ] || { echo "ctest_costs: $record: missing (run the tests first)" >&2; exit 2; }
{ awk 'NF == 3 && $3 >= 10 { printf "%s 1 %.0f\n", $1, $3 }' "$record" | sort -k3,3 -g -r; echo '---'; } \
  > tests/ctest_costs.txt
echo "ctest_costs: $(($(wc -l < tests/ctest_costs.txt) - 1)) tests in tests/ctest_costs.txt"
