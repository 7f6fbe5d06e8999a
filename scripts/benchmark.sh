#!/usr/bin/env bash
# Time, peak memory and quality of this library next to CGAL's Delaunay triangulation
# alone (the floor of every Delaunay-based method), PCL's greedy projection and
# BoundaryEstimation, CGAL's advancing front and Open3D's ball pivoting (when
# python3 can import open3d), on seeded torus and monkey saddle samples and on the
# clouds of a data directory. Every measurement runs in its own process, so that the
# peak memory is its own; one Markdown table is printed at the end (progress on
# stderr).
#
#   bash scripts/benchmark.sh [--sizes 10000,100000|none] [--data DIR]
#        [--methods delaunay,detect,cocone,gp3,boundary_estimation,advancing_front,
#                   ball_pivoting]
#        [--surfaces torus,saddle] [--samplings random,even] [--seed S]
#        [--threads T] [--timeout SECONDS]
#
# Default: sizes 10000,100000,1000000,3000000, every method, one thread (the 1M and
# 3M clouds take hours and several GB: run them on an idle machine). --data takes
# every .ply, .pcd, .xyz and .pts file under DIR; an organized PLY (a range scan) is
# scored against its grid's borders. See apps/cocone_benchmark.cpp for the columns.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
python=${PYTHON:-/usr/bin/python3}

sizes=10000,100000,1000000,3000000
methods=delaunay,detect,cocone,gp3,boundary_estimation,advancing_front,ball_pivoting
surfaces=torus,saddle
samplings=random,even
data=
seed=1
threads=1
timeout=
while [ $# -gt 0 ]; do
  case $1 in
    --sizes) sizes=$2 ;;
    --methods) methods=$2 ;;
    --surfaces) surfaces=$2 ;;
    --samplings) samplings=$2 ;;
    --data) data=${2%/} ;;
    --seed) seed=$2 ;;
    --threads) threads=$2 ;;
    --timeout) timeout=$2 ;;
    *) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2; exit 1 ;;
  esac
  shift 2
done
IFS=, read -r -a sizes <<< "$([ "$sizes" = none ] && echo || echo "$sizes")"
IFS=, read -r -a methods <<< "$methods"
IFS=, read -r -a surfaces <<< "$surfaces"
IFS=, read -r -a samplings <<< "$samplings"

cmake --build "$build" --target cocone_benchmark > /dev/null
bench=$build/cocone_benchmark
if [[ " ${methods[*]} " == *" ball_pivoting "* ]] &&
  ! "$python" -c 'import open3d' 2> /dev/null; then
  echo "open3d is not importable by $python: no ball pivoting" >&2
  methods=("${methods[@]/ball_pivoting/}")
fi
# Open3D and PCL use OpenMP in places; the same number of threads for everyone
# (0, this library's "all cores", is OpenMP's default).
if [ "$threads" -gt 0 ]; then
  export OMP_NUM_THREADS=$threads
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rows=$tmp/rows

# measure CLOUD_NAME FILE TRUTH: every method on one cloud, one line each in $rows.
measure() {
  local name=$1 file=$2 truth=$3 method line status ply=
  for method in "${methods[@]}"; do
    [ -n "$method" ] || continue
    local cmd=("$bench" "$method" "$file" --truth "$truth" --threads "$threads")
    if [ "$method" = ball_pivoting ]; then
      # Open3D reads the same finite points from a plain PLY.
      if [ -z "$ply" ]; then
        ply=$tmp/open3d.ply
        "$bench" convert "$file" "$ply"
      fi
      cmd=("$python" scripts/benchmark_ball_pivoting.py "$ply")
    fi
    [ -n "$timeout" ] && cmd=(timeout --signal=KILL "$timeout" "${cmd[@]}")
    echo "$name: $method" >&2
    status=0
    line=$("${cmd[@]}" 2> "$tmp/stderr" | tail -n 1) || status=$?
    if [ $status -ne 0 ]; then
      line="method=$method failed=exit_$status"
      [ $status -eq 137 ] && [ -n "$timeout" ] && line="method=$method failed=timeout"
      sed 's/^/  /' "$tmp/stderr" >&2
    fi
    echo "  $line" >&2
    printf '%s\t%s\n' "$name" "$line" >> "$rows"
  done
  rm -f "$tmp/open3d.ply"
}

: > "$rows"
for n in "${sizes[@]}"; do
  for surface in "${surfaces[@]}"; do
    for sampling in "${samplings[@]}"; do
      cloud=$tmp/$surface-$sampling-$n.ply
      "$bench" generate "$surface" "$sampling" "$n" "$cloud" "$seed"
      truth=saddle
      [ "$surface" = torus ] && truth=closed
      measure "$surface $sampling $n" "$cloud" $truth
      rm -f "$cloud"
    done
  done
done
if [ -n "$data" ]; then
  while IFS= read -r file; do
    measure "${file#"$data"/}" "$file" auto
  done < <(find "$data" -type f \( -iname '*.ply' -o -iname '*.pcd' -o -iname '*.xyz' \
                                   -o -iname '*.pts' \) | sort)
fi

cat << EOF
Seconds and peak resident memory (MB) of each process, with ratios to CGAL's Delaunay
triangulation alone on the same cloud; $threads thread(s) (0: all cores). Base MB:
the process after reading the cloud (libraries, interpreter), included in the peak.
Boundary edges: edges in one triangle; Euler: V - E + F over the vertices used; border points: reported
(of a mesh: the vertices of its boundary edges), with recall and precision where the
truth is known (torus: none is true; saddle: within 1.5 spacings of the edge; range
scans: the borders of the grid).
EOF
echo
# Two passes over the rows: the Delaunay figures of each cloud, then the table.
awk -F '\t' '
  function field(key,   i, kv) {
    for (i = 1; i <= nf; ++i) {
      split(words[i], kv, "=")
      if (kv[1] == key) return substr(words[i], length(key) + 2)
    }
    return ""
  }
  function seconds(s) { return s == "" ? "–" : sprintf(s < 1 ? "%.3f" : "%.2f", s) }
  function ratio(a, b) {
    return a == "" || b == "" || b == 0 ? "–" : sprintf("%.1f", a / b)
  }
  function or_dash(s) { return s == "" ? "–" : s }
  { nf = split($2, words, " ") }
  NR == FNR {
    if (field("method") == "delaunay" && field("failed") == "") {
      del_s[$1] = field("seconds"); del_mb[$1] = field("peak_mb")
    }
    next
  }
  FNR == 1 {
    print "| cloud | points | method | s | × Del. | peak MB | × Del. | base MB " \
          "| triangles | boundary edges | Euler | border points | recall | precision " \
          "| stages (s) |"
    print "|---|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|"
  }
  {
    if (field("failed") != "") {
      printf "| %s | | %s | failed: %s | | | | | | | | | | | |\n", $1, field("method"),
             field("failed")
      next
    }
    s = field("seconds"); mb = field("peak_mb"); stages = field("stages")
    gsub(/:/, " ", stages); gsub(/,/, ", ", stages)
    printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s " \
           "| %s |\n",
           $1, field("points"), field("method"), seconds(s), ratio(s, del_s[$1]),
           mb, ratio(mb, del_mb[$1]), field("base_mb"), or_dash(field("triangles")),
           or_dash(field("boundary_edges")), or_dash(field("euler")),
           or_dash(field("border_points")), or_dash(field("recall")),
           or_dash(field("precision")), stages
  }
' "$rows" "$rows"
