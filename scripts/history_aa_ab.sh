#!/usr/bin/env bash
# How often the performance gate (scripts/perf_gate.sh) cries wolf, and whether it catches a
# known slowdown, on this machine: `history_aa_ab.sh [CONFIG [COMMIT]]` (default
# harness/configs/table1.json, its quick variant, at HEAD).
#   A/A: $AA_TRIALS gate runs (default 20) of COMMIT against itself; a "regression" is a false
#        alarm (the target: none in at least 19 of 20).
#   A/B: $AB_TRIALS gate runs (default 5) of COMMIT against itself with a slowdown of
#        $PLANTED_SLOWDOWN (default 0.3) planted in $PLANTED_PHASE (default update: the octree's
#        update, or rebuild, and the hat basis's assembly; `step`: the whole step) of the head
#        side only ($MCFBENCH_PLANTED_SLOWDOWN and $MCFBENCH_PLANTED_PHASE,
#        flows/planted_slowdown.h, recorded in each result.json and checked here); each should
#        say "regression".
# Each gate run alternates the two sides over $MCFBENCH_GATE_ROUNDS rounds (default 5), as the
# gate does. Prints a table of the verdicts (pass, regression, inconclusive: the machine was
# shared, error) and whether the targets were met; exits 0 when every trial gave a verdict, 1
# otherwise. Run it on an idle machine: it takes 2 x rounds x (AA_TRIALS + AB_TRIALS) runs of the
# quick config (a build of COMMIT first, cached in ~/.cache/mcfbench-history). Results and logs:
# $AA_AB_OUT (default out/history-aa-ab). The gate's own variables (MCFBENCH_GATE_COMPARE,
# MCFBENCH_GATE_THRESHOLD, MCFBENCH_HISTORY_BUILDS, ...) pass through.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
config=$(realpath "${1:-$root/harness/configs/table1.json}")
repo=${MCFBENCH_GATE_REPO:-$(git rev-parse --show-toplevel 2>/dev/null || echo "$root")}
commit=$(git -C "$repo" rev-parse "${2:-HEAD}^{commit}")
aa=${AA_TRIALS:-20}
ab=${AB_TRIALS:-5}
planted=${PLANTED_SLOWDOWN:-0.3}
phase=${PLANTED_PHASE:-update}
out=$(realpath -m "${AA_AB_OUT:-out/history-aa-ab}")
unset MCFBENCH_PLANTED_SLOWDOWN MCFBENCH_PLANTED_PHASE  # only the A/B head side is slowed, by the runner below
rm -rf "$out"
mkdir -p "$out"

# The head side's runner: the gate's runner (default scripts/history_runner.sh) with the plant.
runner=${MCFBENCH_GATE_RUNNER:-bash $root/scripts/history_runner.sh}
cat >"$out/planted_runner.sh" <<RUNNER
#!/usr/bin/env bash
# history ab's runner for the A/B trials: the head side runs with a planted slowdown.
if [ "\${MCFBENCH_HISTORY_SIDE:-}" = head ]; then
  export MCFBENCH_PLANTED_SLOWDOWN=$planted MCFBENCH_PLANTED_PHASE=$phase
fi
exec $runner "\$@"
RUNNER

# verdict OUT_DIR STATUS: the gate's answer as a word.
verdict() {
  case $2 in 0) echo pass ;; 1) echo regression ;; 3) echo inconclusive ;; *) echo error ;; esac
}

# planted_ok DIR: every head result records the plant and no base result does.
planted_ok() {
  /usr/bin/python3 - "$1" "$planted" "$phase" <<'PY'
import glob, json, sys
d, f, phase = sys.argv[1], float(sys.argv[2]), sys.argv[3]
head = [json.load(open(p)) for p in glob.glob(d + "/head/*.json")]
base = [json.load(open(p)) for p in glob.glob(d + "/base/*.json")]
ok = head and all(r.get("environment", {}).get("planted_slowdown") == f and
                  r.get("environment", {}).get("planted_phase") == phase for r in head) and \
    not any(r.get("environment", {}).get("planted_slowdown") for r in base)
sys.exit(0 if ok else 1)
PY
}

declare -A counts
for kind in aa ab; do
  n=$aa
  [ $kind = ab ] && n=$ab
  for ((i = 1; i <= n; i++)); do
    dir=$out/$kind/$i
    mkdir -p "$dir"
    status=0
    if [ $kind = aa ]; then
      MCFBENCH_GATE_OUT=$dir MCFBENCH_GATE_REPO=$repo \
        bash "$root/scripts/perf_gate.sh" "$config" "$commit" "$commit" >"$dir.log" 2>&1 || status=$?
    else
      MCFBENCH_GATE_OUT=$dir MCFBENCH_GATE_REPO=$repo MCFBENCH_GATE_RUNNER="bash $out/planted_runner.sh" \
        bash "$root/scripts/perf_gate.sh" "$config" "$commit" "$commit" >"$dir.log" 2>&1 || status=$?
    fi
    v=$(verdict "$dir" $status)
    if [ $kind = ab ] && [ "$v" != error ] && ! planted_ok "$dir"; then
      echo "history_aa_ab: $kind trial $i: the head side did not record the planted slowdown" >>"$dir.log"
      v=error
    fi
    echo "history_aa_ab: $kind trial $i/$n: $v (log $dir.log)" >&2
    counts[$kind.$v]=$((${counts[$kind.$v]:-0} + 1))
  done
done

c() { echo "${counts[$1]:-0}"; }
echo "## Gate A/A and A/B: $(basename "$config") (quick) at ${commit:0:12}, ${MCFBENCH_GATE_ROUNDS:-5} rounds, threshold ${MCFBENCH_GATE_THRESHOLD:-0.1}"
echo
echo "| experiment | trials | pass | regression | inconclusive | error |"
echo "|---|---|---|---|---|---|"
echo "| A/A (the same commit twice) | $aa | $(c aa.pass) | $(c aa.regression) (false alarms) | $(c aa.inconclusive) | $(c aa.error) |"
echo "| A/B (head +$planted planted in each $phase) | $ab | $(c ab.pass) | $(c ab.regression) (caught) | $(c ab.inconclusive) | $(c ab.error) |"
echo
aa_ok=no; ab_ok=no
# At most one false alarm in 20 (scaled to the trials run); every planted slowdown caught.
[ $(($(c aa.regression) * 20)) -le "$aa" ] && [ "$(c aa.pass)" -gt 0 ] && aa_ok=yes
[ "$(c ab.regression)" -eq "$ab" ] && [ "$ab" -gt 0 ] && ab_ok=yes
echo "A/A: no regression in at least 19 of 20 (scaled): $aa_ok. A/B: caught in every trial: $ab_ok."
[ $(($(c aa.error) + $(c ab.error))) -eq 0 ]
