#!/usr/bin/env bash
# The performance gate: `perf_gate.sh CONFIG [BASE [HEAD]]` benchmarks BASE (default: the merge
# base of $MCFBENCH_GATE_BRANCH, default main, and HEAD) against HEAD (default HEAD) on this
# machine, alternating them over $MCFBENCH_GATE_ROUNDS rounds (default 5: the fewest at which the
# U test of `compare` can reach its p < 0.05 is 4), and answers (docs/history.md "The gate"):
#   exit 0  pass: no cell of CONFIG's quick variant is slower beyond the threshold;
#   exit 1  regression: a cell is slower by more than $MCFBENCH_GATE_THRESHOLD (default 0.1)
#           with the U test over the rounds agreeing (`mcfbench compare`) in any metric of
#           $MCFBENCH_GATE_METRICS (default: seconds.total seconds.update seconds.solve, the step
#           and its phases), or failed, or lost accuracy;
#   exit 3  inconclusive: a repetition of either side shared the machine with other work
#           (contention.contended), so its timings judge the machine, not the code;
#   exit 2  an error: usage, a side that does not build or run, or sides whose machine, threads
#           or build differ (compare refuses them).
# Results go to $MCFBENCH_GATE_OUT (default out/perf-gate). $MCFBENCH_GATE_RUNNER replaces the
# runner of a commit (scripts/history_runner.sh: build per commit, cached, then
# `mcfbench run --quick`) and $MCFBENCH_GATE_COMPARE the comparison (default build/mcfbench
# compare). The commits are those of the git repository of the current folder
# ($MCFBENCH_GATE_REPO overrides).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 1 ] || { sed -n '2,20p' "$0" >&2; exit 2; }
config=$1
repo=${MCFBENCH_GATE_REPO:-$(git rev-parse --show-toplevel 2>/dev/null || echo "$root")}
head=${3:-HEAD}
base=${2:-$(git -C "$repo" merge-base "${MCFBENCH_GATE_BRANCH:-main}" "$head")}
args=(ab "$config" "$base" "$head" --repo "$repo"
      --rounds "${MCFBENCH_GATE_ROUNDS:-5}" --threshold "${MCFBENCH_GATE_THRESHOLD:-0.1}"
      --out "${MCFBENCH_GATE_OUT:-out/perf-gate}")
[ -n "${MCFBENCH_GATE_RUNNER:-}" ] && args+=(--runner "$MCFBENCH_GATE_RUNNER")
[ -n "${MCFBENCH_GATE_COMPARE:-}" ] && args+=(--compare "$MCFBENCH_GATE_COMPARE")
for m in ${MCFBENCH_GATE_METRICS:-seconds.total seconds.update seconds.solve}; do args+=(--metric "$m"); done
echo "perf_gate: $(git -C "$repo" rev-parse --short=12 "$base") (base) against $(git -C "$repo" rev-parse --short=12 "$head")" >&2
status=0
/usr/bin/python3 "$root/reports/perf_history.py" "${args[@]}" || status=$?
case $status in
  0) echo "perf_gate: pass" >&2 ;;
  1) echo "perf_gate: REGRESSION" >&2 ;;
  3) echo "perf_gate: inconclusive (the machine was shared; rerun on a quiet one)" >&2 ;;
  *) echo "perf_gate: error (exit $status)" >&2; status=2 ;;
esac
exit $status
