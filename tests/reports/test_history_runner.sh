#!/usr/bin/env bash
# The default runner of the history (scripts/history_runner.sh) on the repository's own HEAD,
# with the build taken from the cache (the built mcfbench placed there), so nothing is compiled:
# `history.sh run CONFIG HEAD` checks HEAD out in a worktree, runs the config's quick variant
# with the repetitions asked for and stores one entry with a sample per repetition.
# usage: test_history_runner.sh MCFBENCH; exit 77 (skipped) outside a git checkout.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$1
. "$(dirname "$0")/history_head_setup.sh"
MCFBENCH_HISTORY_BUILDS=$work/builds bash "$root/scripts/history.sh" run "$work/tiny.json" HEAD \
  --repo "$root" --store "$work/store" --repetitions 3 >"$work/log" 2>&1 || { cat "$work/log"; echo "FAIL: history run"; exit 1; }
entry=$(ls "$work"/store/*/tiny/"$head".json 2>/dev/null) || { cat "$work/log"; echo "FAIL: no entry for HEAD"; exit 1; }
/usr/bin/python3 - "$entry" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))
b = e["benchmarks"]
assert sorted(b) == ["solver.name=cholmod", "solver.name=pcg"], b.keys()
assert all(len(v["samples"]) == 3 and v["median"] > 0 for v in b.values()), b
assert e["parents"] and e["date"], e
print("ok: HEAD stored with 3 samples per cell on", e["machine"])
PY
