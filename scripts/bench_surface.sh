#!/usr/bin/env bash
# Surfacer benchmark (issue 5): particles per second per core on one particle frame, for each surface.method of
# `surge surface` and for OpenVDB's vdb_tool (spheres -> level set -> mesh, the same library), side by side,
# single-threaded (taskset to one core, --threads 1). Prints a markdown table.
#
#   scripts/bench_surface.sh [SURGE_BINARY] [FRAME_DIR] [FRAME]
# FRAME_DIR is an output folder of `surge sim` (scene.json + particles/); make a ~1M-particle dam break with
#   surge sim scenes/dam_break.json --set particle_spacing=0.0056 --set output.frames=1 --out /tmp/dam1m --quiet
set -euo pipefail
surge=${1:-build/apps/surge}
dir=${2:-/tmp/dam1m}
frame=${3:-1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/particles"
f=$(printf 'frame_%05d.ply' "$frame")
cp "$dir/particles/$f" "$work/particles/"
cp "$dir/scene.json" "$work/"

# vdb_tool reads only x y z vertices: the same positions as a plain binary PLY.
python3 - "$work/particles/$f" "$work/points.ply" <<'PY'
import struct, sys
src, dst = sys.argv[1], sys.argv[2]
data = open(src, 'rb').read()
end = data.index(b'end_header\n') + len(b'end_header\n')
header = data[:end].decode().splitlines()
n = next(int(l.split()[2]) for l in header if l.startswith('element vertex'))
props = [l.split() for l in header if l.startswith('property')]
size = {'float': 4, 'uint': 4, 'int': 4, 'double': 8, 'uchar': 1}
stride = sum(size[p[1]] for p in props)
out = bytearray()
body = memoryview(data)[end:]
for i in range(n):
    out += bytes(body[i * stride:i * stride + 12])
open(dst, 'wb').write(b'ply\nformat binary_little_endian 1.0\nelement vertex %d\n'
                      b'property float x\nproperty float y\nproperty float z\nend_header\n' % n + out)
print(n, file=open(dst + '.count', 'w'))
PY
n=$(cat "$work/points.ply.count")
spacing=$(python3 -c "import json;print(json.load(open('$work/scene.json'))['particle_spacing'])")
voxel=$(python3 -c "print($spacing / 2)")

seconds() { local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null 2>&1; t1=$(date +%s.%N); python3 -c "print($t1 - $t0)"; }
row() { python3 -c "print('| %s | %.2f | %.2f |' % ('$1', $2, $n / $2 / 1e6))"; }

echo "Frame: $f of $dir, $n particles, spacing $spacing, voxel $voxel (a particle radius), one core."
echo
echo "| method | seconds | M particles/s/core |"
echo "|---|---|---|"
for m in spheres smooth_spheres anisotropic; do
  s=$(seconds taskset -c 0 "$surge" surface "$work" --threads 1 --quiet --set surface.method=$m)
  row "surge $m" "$s"
done
s=$(seconds taskset -c 0 "$surge" surface "$work" --threads 1 --quiet --set surface.method=spheres \
  --set surface.smoothing_steps=0)
row "surge spheres, smoothing_steps=0" "$s"
# vdb_tool: spheres of radius 2 voxels (= spacing, as surge's), band 3 voxels, mesh, as its own example does
# minus the dilate/gauss/erode smoothing (a second row adds it).
s=$(seconds taskset -c 0 vdb_tool -read "$work/points.ply" -points2ls voxel="$voxel" radius=2.0 width=3 \
  -ls2mesh -write "$work/vdb_tool.ply")
row "vdb_tool points2ls + ls2mesh" "$s"
s=$(seconds taskset -c 0 vdb_tool -read "$work/points.ply" -points2ls voxel="$voxel" radius=2.0 width=3 \
  -dilate radius=1 -gauss iter=1 -erode radius=1 -ls2mesh -write "$work/vdb_tool.ply")
row "vdb_tool + dilate, gauss, erode" "$s"
