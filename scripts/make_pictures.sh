#!/usr/bin/env bash
# Render the README's pictures with the tool: bash scripts/make_pictures.sh [DATA_DIR]
# DATA_DIR holds the Stanford bunny range scans (stanford_bunny_scans/bun000.ply).
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
tool=${BUILD_DIR:-build}/pcl_cocone_reconstruction
out=doc/images
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"

# 8,000 area-uniform random points on the unit sphere (seeded).
awk 'BEGIN { srand(3); n = 0;
  while (n < 8000) { x = 2*rand()-1; y = 2*rand()-1; z = 2*rand()-1; r = sqrt(x*x+y*y+z*z);
    if (r > 1 || r < 1e-3) continue; printf "%.7f %.7f %.7f\n", x/r, y/r, z/r; n++ } }' \
  > "$tmp/sphere.xyz"
"$tool" "$tmp/sphere.xyz" "$tmp/sphere.vtk" -q -screenshot "$out/sphere.png"

if [ ! -f example/monkey_saddle.xyz ]; then bash scripts/example.sh > /dev/null; fi
"$tool" example/monkey_saddle.xyz "$tmp/saddle.vtk" -q -screenshot "$out/monkey_saddle.png"

scan="$data/stanford_bunny_scans/bun000.ply"
if [ -f "$scan" ]; then
  "$tool" "$scan" "$tmp/bunny.vtk" -q -screenshot "$out/bunny_boundary.png"
  "$tool" "$scan" "$tmp/bunny_plain.vtk" -q -no_boundary -screenshot "$out/bunny_plain.png"
fi
# The registered scans merged (the .conf lists them with their transforms).
conf="$data/stanford_bunny_scans/bun.conf"
if [ -f "$conf" ]; then
  "$tool" "$conf" "$tmp/bunny_merged.vtk" -q -screenshot "$out/bunny_merged.png"
fi
ls -la "$out"
