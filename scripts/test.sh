#!/usr/bin/env bash
# Set everything up on a fresh Debian bookworm machine, build and run the test suite.
#   bash scripts/test.sh             release build, all tests
#   bash scripts/test.sh --sanitize  the same under AddressSanitizer + UBSan
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
build=${BUILD_DIR:-build}
options=(-DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=ON)
if [ "${1:-}" = "--sanitize" ]; then
  build=${BUILD_DIR:-build-sanitize}
  options=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOCONE_SANITIZE=ON -DBUILD_TESTING=ON)
  # PCL's visualizer frees with the wrong deallocator inside addPolygonMesh.
  export ASAN_OPTIONS=alloc_dealloc_mismatch=0:detect_leaks=1
fi
cmake -S . -B "$build" "${options[@]}"
cmake --build "$build" -j"$(nproc)"
ctest --test-dir "$build" --output-on-failure -j"$(nproc)"
