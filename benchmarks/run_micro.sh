#!/usr/bin/env bash
# Runs the Google Benchmark micro-benchmarks (mcfbench_micro) and keeps one JSON file per commit
# in results/micro/<commit>.json, plus one summary line per run in results/micro/history.jsonl.
# Two such files compare with Google Benchmark's own tool:
#   compare.py benchmarks results/micro/OLD.json results/micro/NEW.json
# Usage: benchmarks/run_micro.sh [extra benchmark flags, e.g. --benchmark_filter=Cholmod]
# Environment: MCFBENCH_BUILD (the build folder, as for scripts/build.sh; default build/),
#              MCFBENCH_MICRO_OUT (default results/micro),
#              MCFBENCH_BENCH_MESH (mesh of the benchmarks, see benchmarks/micro_hat.cpp).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
bin=$build/mcfbench_micro
out_dir=${MCFBENCH_MICRO_OUT:-results/micro}
[ -x "$bin" ] || { echo "run_micro.sh: $bin not built (cmake --build $build --target mcfbench_micro)" >&2; exit 1; }

# Same commit naming as the results of mcfbench (cmake/build_info.cmake): 12 hex, and for an
# uncommitted change "-dirty-" + the first 8 hex of the SHA-1 of `git diff HEAD`.
commit=$(git -C "$root" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
if [ "$commit" != unknown ] && [ -n "$(git -C "$root" status --porcelain --untracked-files=no)" ]; then
  commit="$commit-dirty-$(git -C "$root" diff HEAD | sha1sum | cut -c1-8)"
fi
mkdir -p "$out_dir"
out="$out_dir/$commit.json"
tmp="$out.tmp.$$"
trap 'rm -f "$tmp"' EXIT
"$bin" --benchmark_format=json --benchmark_out="$tmp" --benchmark_out_format=json "$@" >/dev/null
mv "$tmp" "$out"  # a killed run leaves no half-written file under the commit's name

# One history line: commit, date, file, and each benchmark's real time (in its time unit).
/usr/bin/python3 - "$out" "$commit" >>"$out_dir/history.jsonl" <<'PY'
import json, sys, datetime
path, commit = sys.argv[1], sys.argv[2]
data = json.load(open(path))
bench = {b["name"]: {"real_time": b.get("real_time"), "cpu_time": b.get("cpu_time"),
                     "time_unit": b.get("time_unit"), "iterations": b.get("iterations")}
         for b in data.get("benchmarks", []) if b.get("run_type", "iteration") == "iteration"}
print(json.dumps({"commit": commit,
                  "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
                  "file": path, "context": {k: data.get("context", {}).get(k) for k in ("host_name", "num_cpus", "mhz_per_cpu")},
                  "benchmarks": bench}))
PY
echo "run_micro.sh: wrote $out and appended $out_dir/history.jsonl"
