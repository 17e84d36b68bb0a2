#!/usr/bin/env bash
# The history's micro-benchmark runner (scripts/history_micro_runner.sh, chosen by itself for a
# config with a "micro" object) on the repository's own HEAD, with the build taken from the cache
# (the built mcfbench_micro placed there), so nothing is compiled: `history.sh run CONFIG HEAD`
# runs the config's filter with its environment and stores one benchmark per run name with a
# sample per repetition. usage: test_history_micro_runner.sh MCFBENCH_MICRO; exit 77 (skipped)
# outside a git checkout.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$1
exe=mcfbench_micro
. "$(dirname "$0")/history_head_setup.sh"
cat >"$work/micro_tiny.json" <<'JSON'
{"micro": {"benchmark_filter": "^BM_StreamCopy/1/", "environment": {"MCFBENCH_STREAM_MB": "1"}}}
JSON
MCFBENCH_HISTORY_BUILDS=$work/builds bash "$root/scripts/history.sh" run "$work/micro_tiny.json" HEAD \
  --repo "$root" --store "$work/store" --repetitions 3 >"$work/log" 2>&1 || { cat "$work/log"; echo "FAIL: history run"; exit 1; }
entry=$(ls "$work"/store/*/micro_tiny/"$head".json 2>/dev/null) || { cat "$work/log"; echo "FAIL: no entry for HEAD"; exit 1; }
/usr/bin/python3 - "$entry" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))
b = e["benchmarks"]
assert sorted(b) == ["BM_StreamCopy/1/real_time"], b.keys()
assert len(b["BM_StreamCopy/1/real_time"]["samples"]) == 3 and e["metric"] == "real_time", b
print("ok: HEAD's micro-benchmark stored with 3 samples on", e["machine"])
PY
