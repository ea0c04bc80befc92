#!/usr/bin/env bash
# Surge set-up: installs the Debian 12 packages that are missing, configures and builds, then
#   scripts/setup.sh demo   runs scenes/dam_break.json to out/dam_break/dam_break.mp4
#   scripts/setup.sh test   runs the whole test suite (ctest), less the shipped scenes run to their ends
#   scripts/setup.sh scenes runs every shipped scene to its last frame (ctest -L scenes, about ten minutes)
#   scripts/setup.sh build  only builds
#   scripts/setup.sh sanitize  builds everything with ASan and UBSan in build-sanitize and runs the test suite
# Idempotent: a second run installs nothing and rebuilds only what changed. Works as root or through sudo.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
action="${1:-build}"
build_dir="${SURGE_BUILD_DIR:-build}"

packages=(
  g++ cmake ninja-build ccache pkg-config git
  libeigen3-dev libtbb-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  libopenvdb-dev libboost-iostreams-dev libopenvdb-tools
  libembree-dev libosmesa6-dev libstb-dev libtinyobjloader-dev
  libgtest-dev libbenchmark-dev ffmpeg gnuplot-nox zlib1g-dev libbullet-dev
  slurm-wlm munge clang libclang-rt-14-dev
  python3-vtk9 python3-numpy chromium pybind11-dev python3-dev python3-pytest
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "surge setup: installing ${missing[*]}"
  if [ "$(id -u)" -eq 0 ]; then sudo=""; elif command -v sudo >/dev/null; then sudo="sudo"; else
    echo "surge setup: need root or sudo to install: ${missing[*]}" >&2; exit 2; fi
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "surge setup: all packages present"
fi

jobs="$(nproc)"
if [ "$action" = sanitize ]; then
  # Uninstrumented libraries (OpenVDB, TBB, Embree) share std::vector with ours: their container annotations
  # would not match, so ASan's container-overflow check is off; overflows, use after free, leaks and UB are on.
  export ASAN_OPTIONS="detect_container_overflow=0:detect_leaks=1" UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
  export LSAN_OPTIONS="suppressions=$here/tests/lsan_suppressions.txt"
  cmake -S . -B "$build_dir-sanitize" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSURGE_SANITIZE=ON \
    -DSURGE_BUILD_BENCHMARKS=OFF -DSURGE_ARCH="${SURGE_ARCH:-}" -Wno-dev >/dev/null
  cmake --build "$build_dir-sanitize" -j "$jobs"
  exec ctest --test-dir "$build_dir-sanitize" --output-on-failure -j "$jobs" --timeout 2700 -LE scenes
fi
# SURGE_ARCH=x86-64-v3 (say) builds for every node of a cluster from that CPU up instead of for this machine's
# CPU (docs/cluster.md); empty keeps -march=native.
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSURGE_ARCH="${SURGE_ARCH:-}" -Wno-dev >/dev/null
# The demo needs only the program; the tests need everything.
if [ "$action" = demo ]; then target=(--target surge); else target=(); fi
cmake --build "$build_dir" -j "$jobs" "${target[@]}"

case "$action" in
  build) ;;
  demo)
    "$build_dir/apps/surge" run scenes/dam_break.json
    echo "surge setup: video at out/dam_break/dam_break.mp4"
    ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" --timeout 900 -LE scenes
    # The fuzz regression (docs/reliability.md): the readers built again with clang, ASan, UBSan and libFuzzer
    # in a folder of their own, and every committed corpus input run once.
    CC=clang CXX=clang++ cmake -S . -B "$build_dir-fuzz" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSURGE_FUZZ=ON \
      -DSURGE_BUILD_TESTS=OFF -DSURGE_BUILD_BENCHMARKS=OFF -DSURGE_ARCH="${SURGE_ARCH:-}" -Wno-dev >/dev/null
    cmake --build "$build_dir-fuzz" -j "$jobs" --target surge_fuzzers
    ctest --test-dir "$build_dir-fuzz" -L fuzz --output-on-failure -j "$jobs"
    ;;
  scenes)
    # Every shipped scene to its last frame (tests/scenes/scenes_test.sh): about ten minutes on two cores.
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -L scenes
    ;;
  *) echo "usage: scripts/setup.sh [build|demo|test|scenes|sanitize]" >&2; exit 2 ;;
esac
