#!/usr/bin/env bash
# Runs the Google Benchmark micro-benchmarks (mcfbench_micro), keeps the JSON under the commit
# the binary was built from in results/micro/<commit>.json, and stores it in the performance
# history (`mcfbench history add micro FILE`, reports/perf_history.py): one series per
# benchmark, keyed by machine, commit and the config name "micro" as the study results are, so
# `history detect` and `history publish` cover them. Results of uncommitted code are kept as
# files but not stored (a history holds commits).
# Two such files also compare with Google Benchmark's own tool:
#   compare.py benchmarks results/micro/OLD.json results/micro/NEW.json
# Usage: benchmarks/run_micro.sh [extra benchmark flags, e.g. --benchmark_filter=Cholmod]
# Environment: MCFBENCH_BUILD (the build folder, as for scripts/build.sh; default build/),
#              MCFBENCH_MICRO_OUT (default results/micro),
#              MCFBENCH_HISTORY_STORE (default data/history; "none": do not store),
#              MCFBENCH_MICRO_CONFIG (the series' config name, default micro),
#              MCFBENCH_BENCH_MESH (mesh of the benchmarks, see benchmarks/micro_hat.cpp).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
bin=$build/mcfbench_micro
out_dir=${MCFBENCH_MICRO_OUT:-results/micro}
store=${MCFBENCH_HISTORY_STORE:-data/history}
[ -x "$bin" ] || { echo "run_micro.sh: $bin not built (cmake --build $build --target mcfbench_micro)" >&2; exit 1; }

mkdir -p "$out_dir"
tmp=$(mktemp "$out_dir/run.XXXXXX.tmp")
trap 'rm -f "$tmp"' EXIT
"$bin" --benchmark_format=json --benchmark_out="$tmp" --benchmark_out_format=json "$@" >/dev/null
# The commit as mcfbench names it (cmake/build_info.cmake: 12 hex, "-dirty-" and a hash of the
# diff for uncommitted changes), from the binary's own record rather than today's checkout.
commit=$(/usr/bin/python3 -c '
import json, sys
try:
    print(json.loads(json.load(open(sys.argv[1]))["context"]["mcfbench_environment"])["commit"])
except (KeyError, ValueError, TypeError):
    sys.exit("run_micro.sh: %s wrote no mcfbench_environment: no benchmark ran, or it was built before it recorded one" % sys.argv[2])
' "$tmp" "$bin")
out="$out_dir/$commit.json"
mv "$tmp" "$out"  # a killed run leaves no half-written file under the commit's name
echo "run_micro.sh: wrote $out"
if [ "$store" = none ]; then exit 0; fi
case $commit in
  *dirty*|unknown)
    echo "run_micro.sh: $commit is not a commit; not stored in the history $store" >&2
    exit 0 ;;
esac
/usr/bin/python3 "$root/reports/perf_history.py" add "${MCFBENCH_MICRO_CONFIG:-micro}" "$out" \
  --store "$store" --repo "$root"
