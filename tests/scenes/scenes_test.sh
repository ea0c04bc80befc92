#!/usr/bin/env bash
# Every scene in scenes/ simulated to its last frame at its own settings (issue 32): no divergence, every frame
# written, and an end at rest or near it (tests/scenes/check_scene_end.py). ctest -L scenes; its time in
# docs/reliability.md.
#   tests/scenes/scenes_test.sh SURGE SOURCE_DIR WORK_DIR [SCENE ...]
set -uo pipefail
surge="$1" source="$2" work="$3/scenes"
shift 3
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for f in "$source"/scenes/*.json; do names+=("$(basename "$f" .json)"); done
fi
mkdir -p "$work"
failed=0
for name in "${names[@]}"; do
  out="$work/$name"
  rm -rf "$out"
  start=$(date +%s%N)
  if ! "$surge" sim "$source/scenes/$name.json" --quiet --out "$out" 2>"$work/$name.err"; then
    echo "FAIL $name: $(tail -1 "$work/$name.err")"
    failed=1
    continue
  fi
  seconds=$(( ($(date +%s%N) - start) / 1000000 ))e-3
  if verdict=$(python3 "$source/tests/scenes/check_scene_end.py" "$source/scenes/$name.json" "$out"); then
    printf 'ok   %-20s %6.1f s  %s\n' "$name" "$seconds" "$verdict"
  else
    printf 'FAIL %-20s %6.1f s  %s\n' "$name" "$seconds" "$verdict"
    failed=1
  fi
done
exit $failed
