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
  # A scene with whitewater makes it to its last frame too: every frame written, and never more diffuse
  # particles than whitewater.max_particles.
  if python3 -c "import json,sys; sys.exit(0 if json.load(open('$out/scene.json'))['whitewater']['enabled'] else 1)"; then
    if ! "$surge" whitewater "$out" --quiet 2>"$work/$name.err"; then
      echo "FAIL $name (whitewater): $(tail -1 "$work/$name.err")"
      failed=1
      continue
    fi
    if ! python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
scene = json.load(open(os.path.join(out, 'scene.json')))
rows = [l.split(',') for l in open(os.path.join(out, 'whitewater', 'counts.csv')).read().split('\n')[1:] if l]
ok = len(rows) == scene['output']['frames'] + 1 and all(sum(map(int, r[1:4])) <= scene['whitewater']['max_particles'] for r in rows)
sys.exit(0 if ok else 1)
PY
    then
      echo "FAIL $name (whitewater): counts.csv is short or over max_particles"
      failed=1
      continue
    fi
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
