#!/usr/bin/env bash
# Reports on a run that has not finished: cells `mcfbench run` planned (RESULTS_DIR/plans/) without a
# result are warned about ("k of N cells have results"), listed under their study in index.md, and
# their study's figures and tables are marked incomplete; --require-complete refuses to write such a
# report. A complete folder's report is the same with or without its plans. Skips (exit 77, ctest's
# SKIP_RETURN_CODE) where Debian's matplotlib is missing for /usr/bin/python3.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
py=/usr/bin/python3
if ! [ -x "$py" ] || ! "$py" -c "import matplotlib, numpy" 2>/dev/null; then
  echo "SKIP: /usr/bin/python3 has no matplotlib/numpy (apt-get install python3-matplotlib)"; exit 77
fi
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
report() { "$py" "$root/reports/make_report.py" "$@"; }
"$py" "$here/make_fake_results.py" "$work/results" || { echo "FAIL: fake results generator"; exit 1; }
r=$work/results
fail=0
no() { echo "FAIL: $*"; fail=1; }
# The Markdown of one study's section of an index.md.
section() { awk -v s="## $2" '$0 == s {on = 1; next} /^## / {on = 0} on' "$1"; }

# --- Complete: every planned cell has a result. Same files, same exit status as without plans. ---
studies="table1 sphere_error model_error depth_cycles cubature cmcf time_order"
dirs=""; for s in $studies single; do dirs="$dirs $r/$s"; done
report $dirs "$work/full" --references "$r/references" >"$work/full.log" 2>&1 || { cat "$work/full.log"; no "complete: exit status"; }
grep -qi "incomplete\|cells have results" "$work/full.log" && no "complete: warns of an incomplete study"
grep -rqi "incomplete" "$work/full" && no "complete: marked incomplete: $(grep -rli incomplete "$work/full" | tr '\n' ' ')"
for s in $studies; do mv "$r/$s/plans" "$r/$s/plans.off"; done
report $dirs "$work/noplans" --references "$r/references" >"$work/noplans.log" 2>&1 || no "without plans: exit status"
for s in $studies; do mv "$r/$s/plans.off" "$r/$s/plans"; done
diff -r "$work/noplans" "$work/full" >"$work/diff" || { head -20 "$work/diff"; no "complete: the plans change the report"; }

# --- Incomplete: sphere_error lacks cell 2, time_order cells 7, 8 and 9 (cell 6 errored), cubature
# planned its cells and has none yet; an unreadable plan file is skipped with a warning. ---
p=$work/partial
mkdir -p "$p/sphere_error" "$p/time_order" "$p/cubature"
cp -r "$r/sphere_error/cell_000.json" "$r/sphere_error/cell_001.json" "$r/sphere_error/frames" "$r/sphere_error/plans" "$p/sphere_error/"
cp -r "$r/time_order/plans" "$p/time_order/"
for i in 0 1 2 3 4 5 6; do cp "$r/time_order/cell_00$i.json" "$p/time_order/"; done
cp -r "$r/cubature/plans" "$p/cubature/"
echo '{ "cells": [' >"$p/sphere_error/plans/cut_short.json"
report "$p/sphere_error" "$p/time_order" "$p/cubature" "$work/part" --references "$r/references" >"$work/part.log" 2>&1
rc=$?
cat "$work/part.log"
[ $rc = 0 ] || no "incomplete: make_report exited $rc (partial results are a legitimate report)"
grep -q "sphere_error: 2 of 3 cells have results" "$work/part.log" || no "no warning that sphere_error has 2 of 3 cells"
grep -q "time_order: 7 of 10 cells have results" "$work/part.log" || no "no warning that time_order has 7 of 10 cells"
grep -q "cubature: 0 of 3 cells have results" "$work/part.log" || no "no warning that cubature has 0 of 3 cells"
grep -q "cut_short.json" "$work/part.log" || no "an unreadable plan file is not named"
idx=$work/part/index.md
section "$idx" sphere_error >"$work/se.md"
section "$idx" time_order >"$work/to.md"
section "$idx" cubature >"$work/cu.md"
grep -q '^\*\*Incomplete: 2 of 3 planned cells have results' "$work/se.md" || no "index.md: sphere_error not said incomplete"
grep -qF -- '- cell 2 `basis=hat octree.tracking=tracked`' "$work/se.md" || no "index.md: sphere_error's missing cell 2 not listed"
grep -qF -- '- cell 0 ' "$work/se.md" && no "index.md: a present cell listed as missing"
grep -q '^\*\*Incomplete: 7 of 10 planned cells have results' "$work/to.md" || no "index.md: time_order not said incomplete"
grep -qF -- '- cell 7 `dt=0.0005 integrator=explicit`' "$work/to.md" || no "index.md: time_order's missing cell 7 not listed"
grep -qF -- '- cell 8 `dt=0.00025 integrator=explicit`' "$work/to.md" || no "index.md: time_order's missing cell 8 not listed"
grep -qF -- '- cell 9 `dt=0.000125 integrator=crank-nicolson`' "$work/to.md" || no "index.md: time_order's missing cell 9 not listed"
grep -qF -- '- cell 6 `dt=0.001 integrator=explicit`: diverged' "$work/to.md" || no "index.md: the errored cell is no longer listed"
grep -q '^\*\*Incomplete: 0 of 3 planned cells have results' "$work/cu.md" || no "index.md: a study with a plan and no results is left out"
grep -q '^\*\*Incomplete report' "$idx" || no "index.md: no note at the top that the report is incomplete"
# Figures and tables of the incomplete studies say so (title in index.md, a note on the figure,
# which the PNG also carries as its Description); frame strips each show one cell and are not marked.
grep -qF '(incomplete: 2 of 3 cells)](sphere_error.png)' "$idx" || no "index.md: sphere_error.png's title not marked"
grep -qF '(incomplete: 7 of 10 cells)](time_order.png)' "$idx" || no "index.md: time_order.png's title not marked"
grep -aqF 'incomplete: 2 of 3 cells' "$work/part/sphere_error.png" || no "sphere_error.png carries no incomplete mark"
grep -aqF 'incomplete: 7 of 10 cells' "$work/part/time_order.png" || no "time_order.png carries no incomplete mark"
grep -aqi 'incomplete' "$work/part/frames_sphere_error_00.png" && no "a frame strip (one cell) is marked incomplete"
head -1 "$work/part/time_order.md" | grep -q '^\*\*Incomplete: 7 of 10 planned cells have results' || no "time_order.md not marked"
"$py" - "$root/reports" "$work/unit" >"$work/unit.log" 2>&1 <<'PY' || { cat "$work/unit.log"; no "the note drawn on a figure"; }
import sys
sys.path.insert(0, sys.argv[1])
import common
import matplotlib.pyplot as plt
written = []
with common.marked_incomplete(1, 2):
    fig = plt.figure()
    common.save_figure(fig, sys.argv[2], "x", [], "T", written)
assert any(t.get_text() == "incomplete: 1 of 2 cells" for t in fig.texts), [t.get_text() for t in fig.texts]
assert written[0]["title"] == "T (incomplete: 1 of 2 cells)", written
fig = plt.figure()
common.save_figure(fig, sys.argv[2], "y", [], "T", written)
assert not fig.texts and written[1]["title"] == "T", "a mark outlives its study"
PY

# --- Shards in two folders: one alone lacks the other's cells; both together are complete. ---
for i in 0 1; do
  mkdir -p "$work/shard$i/plans"
  cp "$r/depth_cycles/plans/depth_cycles@fake.shard-$i-of-2.json" "$work/shard$i/plans/"
  cp "$r/depth_cycles/cell_00$i.json" "$r/depth_cycles/cell_00$((i + 2)).json" "$work/shard$i/"
done
report "$work/shard0" "$work/one_shard" >"$work/one_shard.log" 2>&1 || no "one shard: exit status"
grep -q "depth_cycles: 2 of 4 cells have results" "$work/one_shard.log" || no "one shard of two not said 2 of 4"
grep -qF -- '- cell 1 `octree.depth=5 solver.cycles=2`' "$work/one_shard/index.md" || no "one shard: the other shard's cell 1 not listed"
report "$work/shard0" "$work/shard1" "$work/two_shards" >"$work/two_shards.log" 2>&1 || no "two shards: exit status"
grep -rqi "incomplete\|cells have results" "$work/two_shards.log" "$work/two_shards" && no "both shards: marked incomplete"

# --- --require-complete: nothing written for the incomplete folders (nor for a study with an
# errored cell, which its figures lack as well); the complete folders report as before. ---
report "$p/sphere_error" "$p/time_order" "$p/cubature" "$work/req" --require-complete >"$work/req.log" 2>&1 \
  && no "--require-complete: exit 0 on incomplete results"
[ -e "$work/req" ] && no "--require-complete: wrote $(ls "$work/req") for incomplete results"
grep -q "sphere_error: 2 of 3 cells have results" "$work/req.log" || { cat "$work/req.log"; no "--require-complete: the incomplete study is not named"; }
report "$r/time_order" "$work/req_err" --require-complete >"$work/req_err.log" 2>&1 && no "--require-complete: exit 0 with an errored cell"
[ -e "$work/req_err" ] && no "--require-complete: wrote a report with an errored cell"
report "$r/sphere_error" "$work/shard0" "$work/shard1" "$work/req_ok" --require-complete >"$work/req_ok.log" 2>&1 \
  || { cat "$work/req_ok.log"; no "--require-complete: complete results refused"; }
[ -s "$work/req_ok/index.md" ] && [ -s "$work/req_ok/sphere_error.png" ] || no "--require-complete: complete results not reported"

[ $fail = 0 ] && echo "incomplete-report test passed"
exit $fail
