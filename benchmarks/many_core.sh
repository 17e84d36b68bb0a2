#!/usr/bin/env bash
# `benchmarks/many_core.sh OUT [THREADS] [REPS]`: the many-core measurements of docs/benchmarks.md
# ("Many cores") in one run sized for a brief loan of a many-core machine (some 300 benchmark
# runs of at least $MCFBENCH_MIN_TIME = 0.2 s each with REPS = 1, after the build). Builds
# mcfbench_micro (scripts/build.sh), then runs the STREAM probes, the compute peak, every phase
# floor (benchmarks/micro_floor.cpp) and the steps of the hat basis (CHOLMOD and the multigrid)
# and of the tracked octree, each at every thread count of THREADS (default "1,2,4,8,0": 0 = all
# cores; $MCFBENCH_THREADS), on the armadillo at 832k faces with the octree at depth 9, REPS
# interleaved repetitions (default 1). Writes OUT/many-core.json (Google Benchmark's JSON) and
# OUT/many-core.md (reports/summarize_micro.py: the floors per thread count, the scaling table and
# the hat step against CHOLMOD's best count). A failed run leaves neither file behind.
# Environment: MCFBENCH_BUILD as for scripts/build.sh; the meshes as in the benchmarks' headers.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: benchmarks/many_core.sh OUT [THREADS] [REPS]" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
out=$1 threads=${2:-1,2,4,8,0} reps=${3:-1}
build=${MCFBENCH_BUILD:-$root/build}
mkdir -p "$out"
"$root/scripts/build.sh" --target mcfbench_micro
export MCFBENCH_THREADS=$threads
export MCFBENCH_FLOOR_MESH=${MCFBENCH_FLOOR_MESH:-cgal:armadillo@faces=832000}
export MCFBENCH_FLOOR_DEPTH=${MCFBENCH_FLOOR_DEPTH:-9}
tmp=$out/many-core.json.tmp
filter='BM_StreamTriad|BM_StreamCopy|BM_PeakFlops|BM_Floor_'
filter+='|BM_Step_HatCholmod|BM_Step_HatMultigrid|BM_Step_Tracked/'
trap 'rm -f "$tmp" "$out/many-core.md.tmp"' EXIT
"$build/mcfbench_micro" --benchmark_filter="$filter" \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_min_time="${MCFBENCH_MIN_TIME:-0.2}" \
  --benchmark_out="$tmp" --benchmark_out_format=json
mv "$tmp" "$out/many-core.json"
/usr/bin/python3 "$root/reports/summarize_micro.py" "$out/many-core.json" >"$out/many-core.md.tmp"
mv "$out/many-core.md.tmp" "$out/many-core.md"
echo "wrote $out/many-core.json and $out/many-core.md"
