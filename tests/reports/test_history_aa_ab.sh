#!/usr/bin/env bash
# scripts/history_aa_ab.sh end to end on a tiny config, one A/A and one A/B trial of 2 rounds
# (too few for the U test to call anything slower, so only the plumbing is judged): both trials
# give a verdict (pass, or inconclusive where the machine was shared), the table is printed, and
# the A/B head side ran with the planted slowdown recorded (the script checks it, else "error").
# The commit's build is taken from the cache (the built mcfbench placed there), as in
# test_history_runner.sh. usage: test_history_aa_ab.sh MCFBENCH; exit 77 outside a git checkout.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$1
. "$(dirname "$0")/history_head_setup.sh"
status=0
AA_TRIALS=1 AB_TRIALS=1 MCFBENCH_GATE_ROUNDS=2 AA_AB_OUT=$work/out MCFBENCH_GATE_REPO=$root \
  MCFBENCH_HISTORY_BUILDS=$work/builds MCFBENCH_GATE_COMPARE="$bin compare" \
  bash "$root/scripts/history_aa_ab.sh" "$work/tiny.json" HEAD >"$work/table" 2>"$work/log" || status=$?
cat "$work/table"
if [ $status != 0 ]; then cat "$work/log" "$work"/out/*/*.log; echo "FAIL: history_aa_ab.sh exit $status"; exit 1; fi
/usr/bin/python3 - "$work/table" <<'PY'
import re, sys
rows = [l for l in open(sys.argv[1]) if l.startswith("| A/")]
assert len(rows) == 2, rows
for r in rows:
    trials, passed, regression, inconclusive, error = [
        int(re.match(r"\s*(\d+)", c).group(1)) for c in r.split("|")[2:7]]
    assert trials == 1 and regression == 0 and error == 0 and passed + inconclusive == 1, r
print("ok: one A/A and one A/B trial, each a verdict; the plant recorded on the head side")
PY
