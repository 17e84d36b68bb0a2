#!/usr/bin/env bash
# The history's runner for micro-benchmark configs (a JSON file with a "micro" object, e.g.
# benchmarks/configs/micro_quick.json): `history_micro_runner.sh CONFIG OUT`, run in a git
# worktree checked out at the commit to measure. Builds that commit's mcfbench_micro (Release,
# through scripts/history_build.sh, cached per commit under $MCFBENCH_HISTORY_BUILDS, default
# ~/.cache/mcfbench-history/<commit>), then runs the benchmarks that the config's
# "benchmark_filter" names with $MCFBENCH_HISTORY_REPETITIONS repetitions (default 5), interleaved
# at random, with the config's "environment" variables set (meshes and depths of the fixtures),
# and leaves Google Benchmark's JSON as OUT/micro.json, which `history` stores one benchmark per
# run name, one sample per repetition. The config is the caller's file, so every commit runs the
# same benchmarks.
set -euo pipefail
config=$1
out=$2
reps=${MCFBENCH_HISTORY_REPETITIONS:-5}
build=$(bash "$(dirname "$0")/history_build.sh" mcfbench_micro)
# The config's settings as shell words: the filter, then NAME=VALUE pairs for env.
mapfile -t settings < <(/usr/bin/python3 - "$config" <<'PY'
import json, sys
path = sys.argv[1]
try:
    m = json.load(open(path))["micro"]
    assert isinstance(m, dict) and isinstance(m.get("benchmark_filter"), str)
except (OSError, ValueError, KeyError, AssertionError) as e:
    sys.exit("%s: expected {\"micro\": {\"benchmark_filter\": REGEX, \"environment\": {...}}} (%s)"
             % (path, e))
print(m["benchmark_filter"])
for k, v in (m.get("environment") or {}).items():
    print("%s=%s" % (k, v))
PY
)
filter=${settings[0]}
env "${settings[@]:1}" "$build/mcfbench_micro" --benchmark_filter="$filter" \
  --benchmark_repetitions="$reps" --benchmark_enable_random_interleaving=true \
  --benchmark_out="$out/micro.json.tmp" --benchmark_out_format=json >&2
mv "$out/micro.json.tmp" "$out/micro.json"
