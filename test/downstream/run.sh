#!/usr/bin/env bash
# Install the package into a temporary prefix, build the downstream project against
# it and run it. Arguments: the build tree, the downstream source directory.
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# DESTDIR: what is installed outside the prefix (the Python package goes into the
# interpreter's site directory) stays in the temporary directory too.
DESTDIR="$work/staged" cmake --install "$build" --prefix /prefix > /dev/null
cmake -S "$src" -B "$work/build" -DCMAKE_PREFIX_PATH="$work/staged/prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/build" > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/build/downstream"
