#!/usr/bin/env bash
# Build the libFuzzer targets with clang, replay the kept corpus (every input that
# ever crashed stays there as a regression), then fuzz each target for a while.
#   bash scripts/fuzz.sh [SECONDS]     (default 60 per target)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
bash scripts/install_deps.sh
build=${BUILD_DIR:-build-fuzz}
case $build in /*) ;; *) build=$PWD/$build ;; esac # the fuzzers run in another directory
CC=clang CXX=clang++ cmake -S fuzz -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
cmake --build "$build" -j"$(nproc)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for target in pipeline readers; do
  echo "== fuzz_$target: replaying fuzz/corpus/$target"
  "$build/fuzz_$target" -rss_limit_mb=2048 fuzz/corpus/$target/* > "$work/replay.log" 2>&1 ||
    { cat "$work/replay.log"; exit 1; }
  mkdir -p "$work/$target"
  cp fuzz/corpus/$target/* "$work/$target/"
  echo "== fuzz_$target: fuzzing for $seconds s"
  (cd "$work" && "$build/fuzz_$target" "$target" -max_total_time="$seconds" \
     -rss_limit_mb=2048 -print_final_stats=1 > "fuzz_$target.log" 2>&1) ||
    { tail -40 "$work/fuzz_$target.log"
      # The report's head (the stack) and the unit itself, kept beside the build:
      # a crash found in a short run may not come back.
      grep -A60 -m1 "ERROR: " "$work/fuzz_$target.log" || true
      mkdir -p "$build/crashes"
      cp "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-* "$build/crashes/" \
        2>/dev/null || true
      for unit in "$build"/crashes/*; do
        [ -f "$unit" ] && echo "kept $unit: $(od -An -tx1 -v "$unit" | tr -d ' \n' | head -c 9000)"
      done
      ls "$work"; exit 1; }
  grep -E "stat::number_of_executed_units|stat::new_units_added" "$work/fuzz_$target.log"
done
