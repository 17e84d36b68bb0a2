#!/usr/bin/env bash
# Reports end to end on fabricated results: every study's figures/tables and the index exist and
# are non-empty. Skips (exit 77, ctest's SKIP_RETURN_CODE) where Debian's matplotlib is missing for /usr/bin/python3.
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
py=/usr/bin/python3
# reports/summarize_micro.py (no matplotlib needed) on a fabricated Google Benchmark file: the step
# ratios, and each multigrid level's share of a W-cycle (100 of 400 ms = 25%; the 40 ms left are
# the copies and the final residual, 10%); a benchmark repeated three times (one slow repetition)
# counts as its median.
[ -x "$py" ] || py=python3
sw=$(mktemp -d)
cat >"$sw/micro.json" <<'JSON'
{"context": {"host_name": "h", "num_cpus": 2, "mhz_per_cpu": 1000, "date": "d"},
 "benchmarks": [
  {"name": "BM_Rebuilt_Cycle/mesh:0/W:1/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 400, "mg_levels": 3, "solve_ms": 400, "wcycle_over_spmv": 4, "depth": 9,
   "level0_visits": 2, "level0_ms": 60, "level1_visits": 2, "level1_ms": 100,
   "level2_visits": 1, "level2_ms": 200},
  {"name": "BM_Step_Tracked/threads:2/iterations:5/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 1000, "update_ms": 1, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "bytes_per_cubature_point": 24},
  {"name": "BM_Step_Rebuilt/threads:2/iterations:2/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 4000, "rebuild_ms": 1, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "steal_ms": 250},
  {"name": "BM_Step_Tracked/threads:1/iterations:5/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 1800, "update_ms": 700, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "bytes_per_cubature_point": 24},
  {"name": "BM_Step_Tracked/threads:1/iterations:5/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 2000, "update_ms": 800, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "bytes_per_cubature_point": 24},
  {"name": "BM_Step_Tracked/threads:1/iterations:5/real_time", "run_type": "iteration", "time_unit": "ms",
   "real_time": 9000, "update_ms": 900, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "bytes_per_cubature_point": 24},
  {"name": "BM_Step_TrackedStabilized/threads:2/vcycle:1/smooth:2/cycles:2/iterations:5/real_time", "run_type": "iteration",
   "time_unit": "ms", "real_time": 700, "update_ms": 1, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "label": "2x V(2,2) m"},
  {"name": "BM_Step_TrackedStabilized/threads:2/vcycle:0/smooth:5/iterations:5/real_time", "run_type": "iteration",
   "time_unit": "ms", "real_time": 900, "update_ms": 1, "set_matrix_ms": 1, "solve_ms": 1, "evaluate_ms": 1, "label": "W(5,5) m"},
  {"name": "BM_Step_Tracked/threads:1_mean", "run_type": "aggregate", "time_unit": "ms", "real_time": 4267}]}
JSON
"$py" "$root/reports/summarize_micro.py" "$sw/micro.json" >"$sw/out.md" 2>&1 || { cat "$sw/out.md"; echo "FAIL: summarize_micro.py"; exit 1; }
for want in '| 1 | 2 | 100 | 25% |' '| outside the cycle (copies, final residual) |  | 40 | 10% |' \
            '| rebuilt / tracked per step | 4× |' '| tracked, 1 thread | 2000 | update 800,' \
            '| tracked 1 thread / 2 threads | 2× |' 'medians of 1–3 repetitions' 'evaluate 1, steal 250 |' \
            '| tracked, stabilized, 2x V(2,2), 2 threads | 700 |' '| tracked, stabilized, W(5,5), 2 threads | 900 |'; do
  grep -qF "$want" "$sw/out.md" || { cat "$sw/out.md"; echo "FAIL: summarize_micro.py lacks: $want"; exit 1; }
done
# The Floors table (benchmarks/micro_floor.cpp): 1e8 bytes in 10 ms is 10 GB/s, half the 2-thread
# triad of 20 GB/s, twice its floor of 5 ms; with a peak of 0.01 GFLOP/s a thread, 1e6 flops take
# 50 ms on two threads, so the phase runs at 0.2x that floor. A skipped level is left out.
cat >"$sw/floor.json" <<'JSON'
{"context": {"host_name": "h", "num_cpus": 2},
 "benchmarks": [
  {"name": "BM_StreamTriad/2/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 1,
   "threads": 2, "bandwidth_GBps": 20},
  {"name": "BM_Floor_HatKernel/threads:2/kernel:0/below:0/real_time", "run_type": "iteration",
   "time_unit": "ms", "real_time": 10, "bytes": 1e8, "flops": 1e6, "threads": 2, "label": "sweep"},
  {"name": "BM_Floor_HatGalerkin/threads:2/below:3/real_time", "run_type": "iteration",
   "time_unit": "ms", "real_time": 0, "error_occurred": true, "error_message": "no such level"}]}
JSON
"$py" "$root/reports/summarize_micro.py" "$sw/floor.json" >"$sw/floor.md" 2>&1 || { cat "$sw/floor.md"; echo "FAIL: summarize_micro.py floors"; exit 1; }
"$py" "$root/reports/summarize_micro.py" --peak-gflops 0.01 "$sw/floor.json" >"$sw/peak.md" 2>&1 || { cat "$sw/peak.md"; echo "FAIL: summarize_micro.py --peak-gflops"; exit 1; }
grep -qF '| HatKernel/threads:2/kernel:0/below:0 (sweep) | 10 | 100 | 1 | 10 | 0.5 | 5 | 2 |' "$sw/floor.md" &&
  grep -qF '| HatKernel/threads:2/kernel:0/below:0 (sweep) | 10 | 100 | 1 | 10 | 0.5 | 50 | 0.2 |' "$sw/peak.md" &&
  ! grep -q 'HatGalerkin' "$sw/floor.md" && ! grep -q 'per step' "$sw/floor.md" ||
  { cat "$sw/floor.md" "$sw/peak.md"; echo "FAIL: summarize_micro.py's floors table"; exit 1; }
# The peak from BM_PeakFlops in the same file (2e7 flop/s on two threads: the same 50 ms floor),
# not from a probe at another thread count.
sed 's|"benchmarks": \[|"benchmarks": [\n  {"name": "BM_PeakFlops/2/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 1, "threads": 2, "flops_per_second": 2e7},\n  {"name": "BM_PeakFlops/1/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 1, "threads": 1, "flops_per_second": 1e12},|' \
  "$sw/floor.json" >"$sw/probe.json"
"$py" "$root/reports/summarize_micro.py" "$sw/probe.json" >"$sw/probe.md" 2>&1 || { cat "$sw/probe.md"; echo "FAIL: summarize_micro.py with BM_PeakFlops"; exit 1; }
grep -qF '| HatKernel/threads:2/kernel:0/below:0 (sweep) | 10 | 100 | 1 | 10 | 0.5 | 50 | 0.2 |' "$sw/probe.md" &&
  grep -qF 'BM_PeakFlops 1 thread 1000 GFLOP/s, 2 threads 0.02 GFLOP/s' "$sw/probe.md" ||
  { cat "$sw/probe.md"; echo "FAIL: summarize_micro.py's floors from BM_PeakFlops"; exit 1; }
# The triad's spread over its repetitions (20 and 30 GB/s: median 25) is printed, and a spread
# over 20% is called out; the single-repetition file above has neither.
sed 's|"bandwidth_GBps": 20},|"bandwidth_GBps": 20},\n  {"name": "BM_StreamTriad/2/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 1, "threads": 2, "bandwidth_GBps": 30},|' \
  "$sw/floor.json" >"$sw/spread.json"
"$py" "$root/reports/summarize_micro.py" "$sw/spread.json" >"$sw/spread.md" 2>&1 || { cat "$sw/spread.md"; echo "FAIL: summarize_micro.py with repetitions"; exit 1; }
grep -qF '2 threads 25 GB/s (20–30 over its repetitions)' "$sw/spread.md" &&
  grep -qF "The triad's repetitions differ by more than 20% (2 threads)" "$sw/spread.md" &&
  ! grep -q "over its repetitions\|differ by more" "$sw/floor.md" ||
  { cat "$sw/spread.md"; echo "FAIL: summarize_micro.py's triad spread"; exit 1; }
# The scaling table of a many-core run (benchmarks/many_core.sh): a benchmark at 1, 2 and 4
# threads, its speed-ups over one thread, and the hat step against CHOLMOD's best thread count
# (2 threads: 400 ms); a file at one or two thread counts has none (above).
cat >"$sw/scaling.json" <<'JSON'
{"context": {"host_name": "h", "num_cpus": 4},
 "benchmarks": [
  {"name": "BM_Step_HatMultigrid/threads:1/cycle:1/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 800},
  {"name": "BM_Step_HatMultigrid/threads:2/cycle:1/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 400},
  {"name": "BM_Step_HatMultigrid/threads:4/cycle:1/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 100},
  {"name": "BM_Step_HatCholmod/threads:1/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 1000},
  {"name": "BM_Step_HatCholmod/threads:2/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 400},
  {"name": "BM_Step_HatCholmod/threads:4/iterations:3/real_time", "run_type": "iteration", "time_unit": "ms", "real_time": 500}]}
JSON
"$py" "$root/reports/summarize_micro.py" "$sw/scaling.json" >"$sw/scaling.md" 2>&1 || { cat "$sw/scaling.md"; echo "FAIL: summarize_micro.py scaling"; exit 1; }
grep -qF '| Step_HatMultigrid/cycle:1 | 800 | 2x | 8x |' "$sw/scaling.md" &&
  grep -qF '| Step_HatCholmod | 1000 | 2.5x | 2x |' "$sw/scaling.md" &&
  grep -qF "at 4 threads: 100 ms, 8x its time on one thread" "$sw/scaling.md" &&
  grep -qF "CHOLMOD's step at its best count (2 threads) 400 ms, so the multigrid step is 0.25x" "$sw/scaling.md" &&
  ! grep -q '^Scaling' "$sw/floor.md" ||
  { cat "$sw/scaling.md"; echo "FAIL: summarize_micro.py's scaling table"; exit 1; }
rm -rf "$sw"
if ! [ -x "$py" ] || ! "$py" -c "import matplotlib, numpy" 2>/dev/null; then
  echo "SKIP: /usr/bin/python3 has no matplotlib/numpy (apt-get install python3-matplotlib)"; exit 77
fi
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
"$py" "$here/make_fake_results.py" "$work/results" || { echo "FAIL: fake results generator"; exit 1; }
studies="table1 sphere_error model_error depth_cycles cubature cmcf time_order hat_multigrid hat_scaling"
dirs=""; for s in $studies single; do dirs="$dirs $work/results/$s"; done
"$py" "$root/reports/make_report.py" $dirs "$work/out" --references "$work/results/references" >"$work/log" 2>&1
rc=$?
cat "$work/log"
[ $rc = 0 ] || { echo "FAIL: make_report.py exited $rc"; exit 1; }
fail=0
expect() { [ -s "$work/out/$1" ] || { echo "FAIL: missing or empty $1"; fail=1; }; }
for f in table1.md sphere_error.png model_error.png depth_cycles.png cubature.png cmcf_00.png \
         cmcf_summary.md time_order.png time_order.md index.md frames_sphere_error_00.png \
         frames_cmcf_00.png frames_cmcf_01.png hat_multigrid.md hat_multigrid.png hat_scaling.png \
         hat_scaling.md; do expect "$f"; done
# hat_multigrid: the cycle at 0.59 of CHOLMOD's step (its update half as long), its contraction and
# distance named.
grep -F "| hat, multigrid W(5,5) x2 | ok |" "$work/out/hat_multigrid.md" | grep -qF "| 0.59 |" ||
  { echo "FAIL: hat_multigrid lacks the cycle's ratio to CHOLMOD"; fail=1; }
grep -F "| hat, multigrid W(5,5) x2 | ok |" "$work/out/hat_multigrid.md" | grep -qF "| 0.10 | 1e-05 | 10 |" ||
  { echo "FAIL: hat_multigrid lacks the cycle's contraction and distance"; fail=1; }
for f in "$work"/out/*.png "$work"/out/*.md; do
  case "$f" in */index.md) continue;; esac
  [ -s "${f%.*}.sources.txt" ] || { echo "FAIL: no sources sidecar for $(basename "$f")"; fail=1; }
done
# Contents: paper values beside ours, fitted orders, singular stop recorded, index links all.
grep -q "Paper (Table 1)" "$work/out/table1.md" || { echo "FAIL: table1 lacks the paper table"; fail=1; }
grep -q "1.4 + 0.22" "$work/out/table1.md" || { echo "FAIL: table1 lacks the paper row beside ours"; fail=1; }
# Step 1's pattern build is the set-up's "+system", not a per-step time.
grep "sphere:vertices=40000" "$work/out/table1.md" | grep -q "(+0.5) | 0.0103 + 0.002 |" ||
  { echo "FAIL: table1 counts step 1's system construction as a per-step time"; fail=1; }
grep -q "spiral:turns=3 at depth .*, tracked: singular (solver: not_positive_definite)" "$work/out/table1.md" ||
  { echo "FAIL: table1 does not name the stopped flow"; fail=1; }
grep "spiral:turns=3" "$work/out/table1.md" | grep -q "×" &&
  { echo "FAIL: table1 gives a speed-up from a stopped flow"; fail=1; }
# time_order's errors are |mean radius − reference| at t = 0.01, the reference the Crank–Nicolson run at
# δ = 1.25e-4 (left out of the fits); against the continuous radius (a flat 1e-3) every slope would be 0.
grep -qE "\| ([a-z]+: )?bdf2 \| 2\.00 \| 3 \|" "$work/out/time_order.md" || { echo "FAIL: bdf2 order not fitted as 2"; fail=1; }
grep -qE "\| ([a-z]+: )?semi-implicit \| 1\.00 \| 3 \|" "$work/out/time_order.md" || { echo "FAIL: semi-implicit order not 1"; fail=1; }
grep -qE "\| ([a-z]+: )?explicit \| 1\.00 \| 2 \| 0\.0005 \| 0\.001 \|" "$work/out/time_order.md" || { echo "FAIL: explicit order not 1"; fail=1; }
grep -qF "Errors are |mean radius − reference| at the final time, the reference being the smallest-δ extrapolated Crank–Nicolson run of the same flow (mcf: δ = 0.000125)" \
  "$work/out/time_order.md" || { echo "FAIL: time_order does not measure against the Crank–Nicolson reference's mean radius"; fail=1; }
grep -q "crank-nicolson" "$work/out/time_order.md" && { echo "FAIL: time_order fits its reference run"; fail=1; }
grep -q "singular" "$work/out/cmcf_summary.md" || { echo "FAIL: singular stop not in cmcf summary"; fail=1; }
# The analytic table: the open cylinder's ring (0.98950 at t = 0.01) beside its references (the
# fake dumbbell runs have no mean radius, so they stay out of it).
grep -qF "| open_cylinder | cmcf | 0.001 | 0.01 | 0.98950 | 0.99001 | 0.99000 | 5.10e-04 | 5.00e-04 |" "$work/out/cmcf_summary.md" \
  || { echo "FAIL: cmcf summary lacks the cylinder's analytic row"; fail=1; }
[ "$(grep -c '^| dumbbell' "$work/out/cmcf_summary.md")" = 3 ] || { echo "FAIL: dumbbell rows in the analytic table"; fail=1; }
# The fake time_order set holds one cell with status "error" (explicit, dt = 1e-3): the figures
# cannot show it, so the index lists it under its study with the reason.
grep -q '^\*\*1 cell(s) errored\*\*' "$work/out/index.md" || { echo "FAIL: index.md does not say a cell errored"; fail=1; }
grep -qF -- '- cell 6 `dt=0.001 integrator=explicit`: diverged' "$work/out/index.md" \
  || { echo "FAIL: index.md does not list the errored cell"; fail=1; }
[ "$(grep -c 'cell(s) errored' "$work/out/index.md")" = 1 ] || { echo "FAIL: errored cells reported for a study without any"; fail=1; }
for f in "$work"/out/*.png "$work"/out/*.md; do
  b=$(basename "$f"); [ "$b" = index.md ] && continue
  grep -q "$b" "$work/out/index.md" || { echo "FAIL: index.md does not link $b"; fail=1; }
done
# Legibility: time_order gives every integrator (and its frozen variant) its own style within a
# flow's panel and the same colour in every panel; legend labels name "solver.name" as "solver" and
# a true flag by its key; cmcf's quasi-conformal panel is logarithmic (a pinching MCF reaches 1e9
# there, which on a linear axis flattens the cMCF and heat curves onto 0).
"$py" - "$root/reports" >"$work/style_log" 2>&1 <<'PY' || { cat "$work/style_log"; echo "FAIL: report legibility checks"; fail=1; }
import sys
sys.path.insert(0, sys.argv[1])
import common, cmcf, time_order
# The stability edge is drawn but not fitted: explicit Euler on MCF, level 4 (the full study).
pts = [(3.9e-5, 1.29e-5), (7.8e-5, 2.58e-5), (1.56e-4, 5.17e-5), (3.1e-4, 1.03e-4), (6.25e-4, 5.11e-2)]
fit = time_order.fitted_points(pts, [1.25e-3, 2.5e-3])
assert fit == pts[:4], fit
assert abs(time_order.fit_slope(fit) - 1.0) < 0.01, time_order.fit_slope(fit)
assert time_order.fitted_points(pts[:1] + pts[4:], [1.25e-3]) == pts[:1] + pts[4:]  # two points: too few to drop one
assert time_order.fitted_points(pts, []) == pts  # nothing unstable: no edge
# A curve drawn on another one says so (heat: explicit Euler and Neumann-2 agree to leading order);
# a different flow or mesh, a 3% gap or a single shared δ is not "on" it; a stable run more is allowed.
e = [(1e-4, 1.00e-5), (2e-4, 2.00e-5), (4e-4, 4.0e-5)]
k = lambda flow, integrator, mesh="icosphere:level=3": (flow, integrator, False, mesh, False)  # noqa: E731 - variant()'s shape
curves = {k("heat", "explicit-euler"): e, k("heat", "neumann2"): [(1e-4, 1.01e-5), (2e-4, 1.99e-5)],
          k("mcf", "neumann2"): e, k("heat", "taylor2"): [(1e-4, 1.03e-5), (2e-4, 2.0e-5)],
          k("heat", "bdf2"): e[:1] + [(8e-4, 2e-5)], k("heat", "bdf2", "icosphere:level=2"): e}
assert time_order.coinciding(curves) == {k("heat", "neumann2"): k("heat", "explicit-euler")}, \
    time_order.coinciding(curves)
flows = ("mcf", "heat")
keys = [(f, g, frozen) for f in flows for g in time_order.INTEGRATORS + ("rk4",) for frozen in (False, True)]
style = time_order.styles(keys)
for f in flows:
    mine = [style[k][:3] for k in keys if k[0] == f]
    assert len(set(mine)) == len(mine), "time_order: two variants of %s share a style" % f
assert style[("mcf", "bdf2", False)][:2] == style[("heat", "bdf2", False)][:2], "time_order: bdf2 changes colour between panels"
alone = time_order.styles([("mcf", "bdf2", False), ("mcf", "rk4", False)])
assert alone[("mcf", "bdf2", False)] == style[("mcf", "bdf2", False)], "time_order: bdf2 changes style between reports"
assert alone[("mcf", "rk4", False)] == style[("mcf", "rk4", False)], "time_order: an unknown integrator's style"
r = {"_stem": "x", "config": {"basis": "octree", "solver": {"name": "multigrid"},
                              "octree": {"refine_input": True, "tracking": "rebuilt"}}}
shown = ["basis", "octree.refine_input", "octree.tracking", "solver.name"]
assert common.label(r, shown) == "basis=octree, refine_input, tracking=rebuilt, solver=multigrid", common.label(r, shown)
r["config"]["octree"]["refine_input"] = False
assert common.label(r, shown) == "basis=octree, tracking=rebuilt, solver=multigrid", common.label(r, shown)
assert common.label(r, ["octree.refine_input"]) == "refine_input=False", common.label(r, ["octree.refine_input"])
# A hat-basis cell beside octree cells (sphere_error's zip) carries the octree defaults: not named.
h = {"_stem": "h", "config": {"basis": "hat", "solver": {"name": "pcg"}, "octree": {"refine_input": False, "tracking": "tracked"}}}
assert common.label(h, shown) == "basis=hat, solver=pcg", common.label(h, shown)
h = {"_stem": "h", "cell": {"assignment": {"basis": "hat", "octree.tracking": "tracked", "solver.name": "pcg"}}}
assert common.label(h, shown) == "basis=hat, solver=pcg", common.label(h, shown)
figures = []
common.save_figure = lambda fig, *args: figures.append(fig)
cells = [{"_stem": f, "_path": f + ".json", "config": {"flow": f, "mesh": "m"}, "status": "ok",
          "steps": [{"step": n, "metrics": {"quasi_conformal": qc}} for n, qc in enumerate(qcs, 1)]}
         for f, qcs in (("mcf", [2.0, 3e9]), ("cmcf", [1.1, 1.2]))]
cmcf.plot_model("m", cells, "unused", None, [], 0)
assert figures and figures[0].axes[1].get_yscale() == "log", "cmcf: quasi-conformal panel is not logarithmic"
PY
# Partial data: each study with a single cell (and frames dropped) must still report cleanly.
solo=""
for s in $studies; do
  mkdir -p "$work/solo/$s"; cp "$work/results/$s/cell_000.json" "$work/solo/$s/"; solo="$solo $work/solo/$s"
done
"$py" "$root/reports/make_report.py" $solo "$work/solo_out" >"$work/solo_log" 2>&1 \
  || { cat "$work/solo_log"; echo "FAIL: make_report.py on one-cell studies"; fail=1; }
[ -s "$work/solo_out/index.md" ] || { echo "FAIL: no index for one-cell studies"; fail=1; }
# Repetitions: a study run with "repetitions": 2 draws repetition 0 of each cell once (harness/cell_hash.cpp's
# cell.key names the repetition; cell.config_key does not), so its figures and tables are those of the
# same study run once: cubature's three curves, time_order's fits (each δ once, the counts of stable runs).
"$py" "$root/reports/make_report.py" "$work/results/cubature" "$work/results/time_order" "$work/once" \
  --references "$work/results/references" >"$work/once_log" 2>&1 || { cat "$work/once_log"; echo "FAIL: make_report.py, one repetition"; fail=1; }
"$py" "$root/reports/make_report.py" "$work/results/repeated/cubature" "$work/results/repeated/time_order" "$work/twice" \
  --references "$work/results/references" >"$work/twice_log" 2>&1 || { cat "$work/twice_log"; echo "FAIL: make_report.py, two repetitions"; fail=1; }
for f in cubature.png time_order.png time_order.md; do
  cmp -s "$work/once/$f" "$work/twice/$f" || { echo "FAIL: $f of a study run twice differs from its single run"; fail=1; }
done
[ "$(wc -l <"$work/twice/cubature.sources.txt")" = 3 ] || { echo "FAIL: cubature.png of two repetitions draws $(wc -l <"$work/twice/cubature.sources.txt") cells, not 3"; fail=1; }
# Commits: a folder holding two commits' results of the same cells reports the newest commit's (by
# file time: c0ffee's cells 0 and 1) and the older one's cell 2 that the newer did not run, says so on
# stderr and in index.md, and table1 has a row per model and commit, each from its own commit's times.
"$py" "$root/reports/make_report.py" "$work/results/commits/cubature" "$work/results/commits/table1" "$work/commits" \
  >"$work/commits_log" 2>&1 || { cat "$work/commits_log"; echo "FAIL: make_report.py on two commits"; fail=1; }
[ "$(xargs -n1 basename <"$work/commits/cubature.sources.txt" | sort | tr '\n' ' ')" = "a_old_002.json b_new_000.json b_new_001.json " ] ||
  { cat "$work/commits/cubature.sources.txt"; echo "FAIL: cubature of two commits does not draw the newest commit's cells"; fail=1; }
for s in cubature table1; do
  grep -q "^warning: $s: results of 2 commits: c0ffee .*; 0ld0ld .*2 older result(s) of the same cells left out" "$work/commits_log" ||
    { cat "$work/commits_log"; echo "FAIL: no warning that $s mixes commits"; fail=1; }
  awk -v s="## $s" '$0 == s {on = 1; next} /^## / {on = 0} on' "$work/commits/index.md" |
    grep -q '^\*\*Several commits:\*\* .*c0ffee.*0ld0ld' || { echo "FAIL: index.md does not name $s's commits"; fail=1; }
done
grep -F "| sphere:vertices=40000 @c0ffee |" "$work/commits/table1.md" | grep -qF "(+0.5) | 0.0103 + 0.002 |" ||
  { cat "$work/commits/table1.md"; echo "FAIL: table1 does not time the newest commit alone"; fail=1; }
grep -qF "| cgal:bunny00 @0ld0ld |" "$work/commits/table1.md" || { echo "FAIL: table1 lacks the older commit's model"; fail=1; }
# Several meshes in one study: time_order measures each mesh's runs (and a quick run's) against the
# reference run on that mesh (of that quick flag) and fits them apart, each at its true order; depth_cycles
# draws a line per mesh and depth (residuals) and per mesh and number of cycles (Hausdorff distance).
"$py" "$root/reports/make_report.py" "$work/results/meshes/time_order" "$work/meshes" --references "$work/results/references" \
  >"$work/meshes_log" 2>&1 || { cat "$work/meshes_log"; echo "FAIL: make_report.py on several meshes"; fail=1; }
for where in "icosphere:level=3 (full)" "icosphere:level=2 (full)" "icosphere:level=3 (quick)"; do
  for want in "semi-implicit | 1.00 | 3 | 0.001 | — | 1" "bdf2 | 2.00 | 3 | 0.001 | — | 2" "explicit | 1.00 | 2 | 0.0005 | 0.001 | —"; do
    grep -qF "| mcf on $where: $want |" "$work/meshes/time_order.md" ||
      { cat "$work/meshes/time_order.md"; echo "FAIL: time_order on several meshes lacks: mcf on $where: $want"; fail=1; }
  done
done
[ "$(grep -c '^| mcf' "$work/meshes/time_order.md")" = 9 ] || { echo "FAIL: time_order on several meshes: not 9 rows"; fail=1; }
"$py" - "$root/reports" "$work/results/meshes/depth_cycles" >"$work/dc_log" 2>&1 <<'PY' || { cat "$work/dc_log"; echo "FAIL: depth_cycles on two meshes"; fail=1; }
import sys
sys.path.insert(0, sys.argv[1])
import common, depth_cycles
figures = []
common.save_figure = lambda fig, *args: figures.append(fig)
depth_cycles.make(common.load_results(sys.argv[2]), "unused", None, [])
residual, hausdorff = figures[0].axes
lines = lambda ax: {l.get_label(): list(l.get_xdata()) for l in ax.get_lines()}  # noqa: E731
want = {"icosphere:level=%d, depth %d" % (m, d): [1, 2] for m in (3, 2) for d in (5, 6)}
assert lines(residual) == want, lines(residual)
want = {"icosphere:level=%d, %d W-cycle%s" % (m, c, "s" if c > 1 else ""): [5, 6] for m in (3, 2) for c in (1, 2)}
assert lines(hausdorff) == want, lines(hausdorff)
PY
# Frame strips, at most 8 a study, spread over the flows, then the meshes: of 3 flows × 7 meshes (cells
# numbered flow-major) every flow and every mesh gets a strip (the first 8 cells were 7 MCF strips and
# one heat strip), picked round-robin (mcf 10, heat 11, cmcf 12, mcf 13, …, heat 10) and numbered in
# cell order; the 13 cells left out are counted on stdout and listed in index.md.
"$py" "$root/reports/make_report.py" "$work/results/strips/cmcf" "$work/strips" >"$work/strips_log" 2>&1 ||
  { cat "$work/strips_log"; echo "FAIL: make_report.py on 21 cells with frames"; fail=1; }
got=$(grep '^### Frames: ' "$work/strips/index.md" | sed 's/^### Frames: //; s/torus:n_major=//' | tr '\n' ' ')
want="flow=mcf, mesh=10 flow=mcf, mesh=13 flow=mcf, mesh=16 flow=heat, mesh=10 flow=heat, mesh=11 flow=heat, mesh=14 flow=cmcf, mesh=12 flow=cmcf, mesh=15 "
[ "$got" = "$want" ] || { echo "FAIL: frame strips not spread over flows and meshes: $got"; fail=1; }
[ -s "$work/strips/frames_cmcf_07.png" ] && ! [ -e "$work/strips/frames_cmcf_08.png" ] || { echo "FAIL: not 8 frame strips"; fail=1; }
grep -q '^frames: cmcf: 21 cells saved frames, strips for 8 of them (at most 8, spread over flow, mesh); the others are listed in index.md' \
  "$work/strips_log" || { cat "$work/strips_log"; echo "FAIL: no note counting the cells without a strip"; fail=1; }
grep '^Frame strips for 8 of the 21 cells that saved frames' "$work/strips/index.md" | grep -o 'cell [0-9]*' | tr '\n' ' ' |
  grep -qx 'cell 1 cell 2 cell 4 cell 5 cell 9 cell 10 cell 12 cell 13 cell 14 cell 15 cell 17 cell 18 cell 20 ' ||
  { grep '^Frame strips' "$work/strips/index.md"; echo "FAIL: index.md does not list the cells without a strip"; fail=1; }
[ $fail = 0 ] && echo "reports test passed: $(ls "$work"/out/*.png | wc -l) figures, $(ls "$work"/out/*.md | wc -l) Markdown files"
exit $fail
