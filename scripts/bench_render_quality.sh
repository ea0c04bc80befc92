#!/usr/bin/env bash
# The path tracer's samples and denoiser against a many-sample reference (issue 15): renders a few frames of a
# demo run with REFERENCE_SAMPLES samples a pixel and no filter (once; kept beside the run and reused), then
# prints, for each setting, the seconds a frame takes and the image error against that reference
# (bench/render_quality.cpp). A reference of N samples is itself off by about 1/sqrt(N / 8) of the 8-sample
# image's error: 1024 samples, 9%. It must have many more samples than the settings it judges: a pixel's
# sample s draws the same random numbers beyond its first bounces in every image, so an image of 8 samples
# shares them with 8 of the reference's (with 16, half of it: 8 unfiltered samples then look better than they
# are; with 1024, under 1%).
#
#   scripts/bench_render_quality.sh [BUILD_DIR] [RUN_DIR] [FRAMES] [REFERENCE_SAMPLES] [SETTINGS...]
# Defaults: build, out/dam_break (made with `surge run scenes/dam_break.json` if it has no surfaces), frames
# 30,60,90, 1024 samples, settings 8:0 1:0 1:1 2:0 2:1 4:0 4:1 8:1 (SAMPLES:DENOISE).
set -euo pipefail
build=${1:-build}
run=${2:-out/dam_break}
frames=${3:-30,60,90}
samples=${4:-1024}
shift $(($# < 4 ? $# : 4))
settings=("$@")
[ ${#settings[@]} -gt 0 ] || settings=(8:0 1:0 1:1 2:0 2:1 4:0 4:1 8:1)
surge="$build/apps/surge"

[ -d "$run/surface" ] || "$surge" run scenes/dam_break.json --out "$run" --quiet
reference="$run.reference$samples"
mkdir -p "$reference/surface"
cp "$run/scene.json" "$run/surface_settings.json" "$reference/"
missing=0
for f in ${frames//,/ }; do
  name=$(printf 'frame_%05d' "$f")
  cp -p "$run/surface/$name.ply" "$reference/surface/"
  [ -f "$reference/frames/$name.png" ] || missing=1
done
if [ $missing = 1 ]; then
  echo "bench_render_quality: rendering the reference ($samples samples a pixel) in $reference" >&2
  "$surge" render "$reference" --resume --quiet --set render.samples="$samples" --set render.denoise=0
fi
"$build/bench/surge_render_quality" "$run" "$reference" "$frames" "${settings[@]}"
