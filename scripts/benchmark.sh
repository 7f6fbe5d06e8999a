#!/usr/bin/env bash
# Stage timings and peak memory next to CGAL's Delaunay alone, each in its own process:
#   bash scripts/benchmark.sh [sizes...]      (default: 100000 1000000)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
cmake --build "$build" --target cocone_benchmark > /dev/null
sizes=("$@")
[ ${#sizes[@]} -eq 0 ] && sizes=(100000 1000000)
for n in "${sizes[@]}"; do
  for surface in torus saddle; do
    for what in delaunay detect pipeline; do
      "$build/cocone_benchmark" "$what" "$surface" "$n"
    done
  done
done
