#!/usr/bin/env bash
# One flow divided across MPI ranks (distributed/, docs/petsc.md "Across MPI ranks"):
# - `mpirun -n 1, 2, 4 mcfbench flow` on the hat basis (one rank: the one-process flow) — MCF on a sphere and cMCF with unit area
#   on a scanned model, with PETSc's CG + GAMG, the distributed surface multigrid and CG
#   preconditioned by its cycle, each at a tight tolerance — ends within 1e-8 of the bounding
#   box's diagonal of the one-process CHOLMOD flow; so do a fixed boundary (an open cylinder), the
#   lumped mass, BDF2 and Taylor-2, and the frames written under ranks;
# - result.json records the ranks, the partitioner, per rank its owned and ghost vertices (the
#   owned ones adding up to the mesh's), its peak memory, and per phase the slowest rank and the
#   imbalance; the fixed cycles of the multigrid are converged only at their residual bound;
# - bad input fails on every rank with one message and no output: a missing file, the octree
#   basis, a solver that runs in one process, an option PETSc refuses; a flow asking for 2 ranks
#   without them is refused;
# - a study cell with mpi_ranks 2 runs under the mpirun `mcfbench run` starts.
#
# usage: test_mpi_flow.sh MCFBENCH
#
# Exits 77 (skipped) without mpirun or in a build without PETSc. Open MPI refuses to run as root
# unless told: the two OMPI_ALLOW_RUN_AS_ROOT variables (CI runs as root).
set -u
mcfbench=${1:?usage: test_mpi_flow.sh MCFBENCH}
py=/usr/bin/python3
command -v mpirun >/dev/null 2>&1 || { echo "skipped: no mpirun (apt-get install openmpi-bin)"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
fail() { echo "FAIL: $*"; exit 1; }
if ! "$mcfbench" flow --mesh sphere:vertices=500 --solver petsc --threads 1 --steps 1 \
    --out "$work/probe" >"$work/probe.log" 2>&1; then
  if grep -q "built without PETSc" "$work/probe.log"; then echo "skipped: built without PETSc"; exit 77; fi
  cat "$work/probe.log"; fail "a one-process PETSc flow failed"
fi

# compare.py EXACT DIVIDED RANKS: final.ply (and frames) vertex by vertex, and the records.
cat >"$work/compare.py" <<'PY'
import glob, json, os, sys
import numpy as np
def read(path):
    d = open(path, "rb").read()
    h = d.index(b"end_header\n") + len(b"end_header\n")
    n = int([l for l in d[:h].decode().split("\n") if l.startswith("element vertex")][0].split()[-1])
    return np.frombuffer(d[h:h + 24 * n], dtype="<f8").reshape(n, 3)
exact, divided, ranks = sys.argv[1], sys.argv[2], int(sys.argv[3])
a = read(exact + "/final.ply")
diag = np.linalg.norm(a.max(0) - a.min(0))
dev = np.abs(a - read(divided + "/final.ply")).max() / diag
frames = sorted(os.path.basename(f) for f in glob.glob(divided + "/frame_*.ply"))
for f in frames:
    dev = max(dev, np.abs(read(exact + "/" + f) - read(divided + "/" + f)).max() / diag)
r = json.load(open(divided + "/result.json"))
problems = []
if ranks == 1:  # mpirun -n 1 runs the one-process flow
    print("%s in one process: %.3g of the diagonal" % (os.path.basename(divided), dev))
    sys.exit(0 if dev < 1e-8 and r["status"] == "ok" else 1)
d = r["distribution"]
if dev >= 1e-8: problems.append("%.3g of the diagonal from the one-process CHOLMOD flow" % dev)
if r["status"] != "ok": problems.append("status " + r["status"])
if d["ranks"] != ranks or len(d["owned_vertices"]) != ranks: problems.append("ranks %s" % d["ranks"])
if sum(d["owned_vertices"]) != r["system"]["dimension"]: problems.append("owned vertices %s" % d["owned_vertices"])
if ranks > 1 and min(d["ghost_vertices"]) <= 0: problems.append("no ghosts %s" % d["ghost_vertices"])
if len(d["peak_memory_bytes"]) != ranks or min(d["peak_memory_bytes"]) <= 0: problems.append("peak memory")
for phase in ("setup", "update", "solve", "steps"):
    p = d["phase_seconds"][phase]
    if not (p["max"] >= p["mean"] >= 0 and p["imbalance"] >= 1): problems.append("phase " + phase)
if ranks > 1 and d["partitioner"] not in ("ptscotch", "blocks of the bandwidth ordering"):
    problems.append("partitioner " + d["partitioner"])
for s in r["steps"]:
    if s["solver"]["status"] != "converged": problems.append("step %d %s" % (s["step"], s["solver"]["status"]))
print("%s on %d ranks: %.3g of the diagonal, %d frames, owned %s, ghosts %s, partitioner %s" % (
    os.path.basename(divided), ranks, dev, len(frames), d["owned_vertices"], d["ghost_vertices"],
    d["partitioner"]))
if problems: print("  problems: " + "; ".join(problems))
sys.exit(1 if problems else 0)
PY

# case NAME FLOW-FLAGS...: the one-process CHOLMOD flow, then each solver on 1, 2 and 4 ranks.
case_() {
  local name=$1
  shift
  "$mcfbench" flow "$@" --solver cholmod --threads 1 --out "$work/$name-exact" >"$work/$name.log" 2>&1 ||
    { cat "$work/$name.log"; fail "$name: the one-process flow failed"; }
  local solver ranks
  for solver in "petsc" "multigrid --cycle V --smooth 2 --tolerance 1e-12 --cycles 100" \
      "pcg --preconditioner multigrid --cycle V --smooth 2 --tolerance 1e-12"; do
    for ranks in 1 2 4; do
      # shellcheck disable=SC2086
      mpirun -n "$ranks" "$mcfbench" flow "$@" --solver $solver --threads 1 \
        --out "$work/$name-$ranks" >"$work/$name-$ranks.log" 2>&1 ||
        { cat "$work/$name-$ranks.log"; fail "$name, $solver, $ranks ranks: the flow failed"; }
      "$py" "$work/compare.py" "$work/$name-exact" "$work/$name-$ranks" "$ranks" ||
        fail "$name, $solver, $ranks ranks"
    done
  done
}
tight=(--tolerance 1e-12)
case_ mcf --mesh sphere:vertices=3000 --dt 1e-3 --steps 3 --save-every 3
case_ cmcf --mesh cgal:elephant --flow cmcf --normalize-area --dt 1e-3 --steps 3

# Fewer combinations: a held boundary, the lumped mass, two integrators; PETSc's CG + GAMG on 2
# and 4 ranks.
more() {
  local name=$1
  shift
  "$mcfbench" flow "$@" --solver cholmod --threads 1 --out "$work/$name-exact" >"$work/$name.log" 2>&1 ||
    { cat "$work/$name.log"; fail "$name: the one-process flow failed"; }
  for ranks in 2 4; do
    mpirun -n "$ranks" "$mcfbench" flow "$@" --solver petsc "${tight[@]}" --threads 1 \
      --out "$work/$name-$ranks" >"$work/$name-$ranks.log" 2>&1 ||
      { cat "$work/$name-$ranks.log"; fail "$name, $ranks ranks: the flow failed"; }
    "$py" "$work/compare.py" "$work/$name-exact" "$work/$name-$ranks" "$ranks" || fail "$name, $ranks ranks"
  done
}
more boundary --mesh open_cylinder:radius=0.5,length=2,n_around=48 --dt 1e-3 --steps 3
more lumped --mesh sphere:vertices=3000 --mass lumped --dt 1e-3 --steps 3
more bdf2 --mesh cgal:elephant --integrator bdf2 --dt 1e-4 --steps 3
more taylor2 --mesh sphere:vertices=3000 --integrator taylor2 --dt 1e-5 --steps 3
"$py" - "$work/boundary-2/result.json" <<'PY' || fail "the boundary's held functions"
import json, sys
r = json.load(open(sys.argv[1]))
held = r["system"]["dimension"] - r["system"]["free_functions"]
print("open cylinder: %d held functions of %d" % (held, r["system"]["dimension"]))
sys.exit(0 if held == 2 * 48 else 1)
PY

# A rerun on the same ranks gives the same bits (the surface multigrid: its hierarchy, Galerkin
# products, sweeps and rank-ordered sums are fixed per partition, and PT-Scotch's partition is made
# the same every run).
for i in 1 2; do
  mpirun -n 2 "$mcfbench" flow --mesh cgal:elephant --solver pcg --preconditioner multigrid \
    --threads 1 --dt 1e-3 --steps 2 --out "$work/again-$i" >"$work/again.log" 2>&1 ||
    { cat "$work/again.log"; fail "the rerun"; }
done
cmp -s "$work/again-1/final.ply" "$work/again-2/final.ply" || fail "two runs on 2 ranks differ"
echo "a rerun on 2 ranks: the same bits"

# The default fixed cycles (one W(5,5)) across ranks: each step converged at its residual bound.
mpirun -n 2 "$mcfbench" flow --mesh sphere:vertices=3000 --solver multigrid --threads 1 --dt 1e-3 \
  --steps 3 --out "$work/cycles" >"$work/cycles.log" 2>&1 || { cat "$work/cycles.log"; fail "fixed cycles"; }
"$py" - "$work/cycles/result.json" <<'PY' || fail "the fixed cycles' bound"
import json, sys
r = json.load(open(sys.argv[1]))
bound = r["config"]["solver"]["residual_bound"]
steps = [(s["solver"]["status"], s["solver"]["relative_residual"]) for s in r["steps"]]
print("fixed cycles on 2 ranks, bound %g: %s, %d levels" % (bound, steps, r["system"]["levels"]))
sys.exit(0 if r["system"]["levels"] > 1 and all(s == "converged" and x <= bound for s, x in steps) else 1)
PY

# The guard's two stages across ranks: one V(1,1)-cycle ends far above a bound of 1e-10, so CG by
# the cycle finishes each step; with one CG iteration allowed and a bound of 1e-12, MUMPS does.
# Both end at the bound and within 1e-8 of the one-process CHOLMOD flow. The sphere's steps after
# the first fit their prediction (smooth steps), so --bound-smooth-steps holds them to the bound;
# without it they keep their cycle and say so.
"$mcfbench" flow --mesh sphere:vertices=3000 --solver cholmod --threads 1 --dt 1e-3 --steps 3 \
  --out "$work/guard-exact" >"$work/guard.log" 2>&1 || { cat "$work/guard.log"; fail "the guard's reference"; }
for stage in "cg:--residual-bound 1e-10 --bound-smooth-steps" \
  "direct:--residual-bound 1e-12 --direct-after 1 --bound-smooth-steps" "smooth:--residual-bound 1e-10"; do
  name=${stage%%:*}
  mpirun -n 2 "$mcfbench" flow --mesh sphere:vertices=3000 --solver multigrid --cycle V --smooth 1 \
    --cycles 1 ${stage#*:} --threads 1 --dt 1e-3 --steps 3 --out "$work/guard-$name" \
    >"$work/guard.log" 2>&1 || { cat "$work/guard.log"; fail "the guard ($name)"; }
  "$py" - "$work/guard-exact" "$work/guard-$name" "$name" <<'PY' || fail "the guard ($name)"
import json, sys
import numpy as np
def read(p):
    d = open(p, "rb").read()
    h = d.index(b"end_header\n") + len(b"end_header\n")
    n = int([l for l in d[:h].decode().split("\n") if l.startswith("element vertex")][0].split()[-1])
    return np.frombuffer(d[h:h + 24 * n], dtype="<f8").reshape(n, 3)
exact, guarded, stage = sys.argv[1:4]
a = read(exact + "/final.ply")
dev = np.abs(a - read(guarded + "/final.ply")).max() / np.linalg.norm(a.max(0) - a.min(0))
r = json.load(open(guarded + "/result.json"))
bound = r["config"]["solver"]["residual_bound"]
steps = r["steps"]
ok = all(s["solver"]["status"] == "converged" and s["solver"]["relative_residual"] <= bound
         for s in (steps[:1] if stage == "smooth" else steps))
fb = [s["solver"].get("fallback", {}) for s in steps]
if stage == "smooth":
    ok = ok and all(s["solver"]["status"] == "max_iterations" and s["solver"]["relative_residual"] > bound
                    and "kept: a smooth step" in s["solver"]["message"] for s in steps[1:])
    print("smooth steps on 2 ranks: %s" % [s["solver"]["message"][-60:] for s in steps[1:]])
    sys.exit(0 if ok else 1)
if stage == "cg":
    ok = ok and all(f.get("iterations", 0) > 0 and f.get("direct_solves", 0) == 0 for f in fb)
else:
    ok = ok and all(f.get("direct_solves", 0) > 0 for f in fb)
print("the guard (%s) on 2 ranks: %.3g of the diagonal, fallbacks %s" % (stage, dev, fb))
sys.exit(0 if ok and dev < 1e-8 else 1)
PY
done

# Bad input: one message, from rank 0, and nothing written.
refused() {
  local what=$1 expect=$2
  shift 2
  mpirun -n 2 "$mcfbench" flow "$@" --threads 1 --steps 1 --out "$work/refused" >"$work/refused.log" 2>&1 &&
    fail "$what was not refused"
  [ "$(grep -c 'mcfbench: error:' "$work/refused.log")" = 1 ] ||
    fail "$what: not one message: $(grep 'mcfbench: error:' "$work/refused.log")"
  grep -q "$expect" "$work/refused.log" || fail "$what: no message saying '$expect': $(cat "$work/refused.log")"
  [ ! -e "$work/refused" ] || fail "$what: the refused run wrote $work/refused"
  echo "refused under 2 ranks, with one message: $what"
}
refused "a missing file" "no-such-file.ply" --mesh "$work/no-such-file.ply" --solver petsc
refused "the octree basis" 'basis: "octree" runs in one process' --mesh sphere:vertices=500 --basis octree --solver petsc
refused "CHOLMOD" 'solver.name: "cholmod" runs in one process' --mesh sphere:vertices=500 --solver cholmod
refused "a KSP type PETSc lacks" "Unable to find requested KSP type" --mesh sphere:vertices=500 \
  --solver petsc --petsc-options="-ksp_type nonsense"
refused "an option nothing reads" "PETSc did not use -pc_type_jacobi" --mesh sphere:vertices=500 \
  --solver petsc --petsc-options="-pc_type_jacobi"
# A flow that asks for 2 ranks is refused when not started on them, writing nothing.
"$mcfbench" flow --mesh sphere:vertices=500 --solver petsc --threads 1 --mpi-ranks 2 --out "$work/unranked" \
  >"$work/unranked.log" 2>&1 && fail "--mpi-ranks 2 without mpirun was not refused"
grep -q 'mpi_ranks: 2 ranks asked for, but this process is one of 1' "$work/unranked.log" ||
  fail "no refusal message: $(cat "$work/unranked.log")"
[ ! -e "$work/unranked" ] || fail "the refused run wrote $work/unranked"

# A study cell with mpi_ranks 2: `mcfbench run` starts it under mpirun itself, and its frames and
# reference distance are made as for the one-process cell beside it.
cat >"$work/ranks.json" <<'JSON'
{"name": "ranks", "defaults": {"mesh": "sphere:vertices=3000", "solver.name": "petsc", "threads": 1,
  "dt": 1e-3, "steps": 3},
 "axes": {"mpi_ranks": [1, 2]},
 "metrics": {"frames": [3], "reference": {"mpi_ranks": 1}, "sphericity": true}}
JSON
"$mcfbench" run "$work/ranks.json" --out "$work/ranks" >"$work/ranks.log" 2>&1 ||
  { cat "$work/ranks.log"; fail "the study with an mpi_ranks cell failed"; }
"$py" - "$work/ranks" <<'PY' || exit 1
import glob, json, sys
cells = [json.load(open(f)) for f in glob.glob(sys.argv[1] + "/*.json")]
cells = {c["config"].get("mpi_ranks", 1): c for c in cells if "cell" in c}
two = cells[2]
ok = sorted(cells) == [1, 2] and two["status"] == "ok" and two["distribution"]["ranks"] == 2
d = two["reference_distance"][0]
ok = ok and d["step"] == 3 and d["max"] < 1e-8
ok = ok and two["peak_memory_scope"] == "rank 0 of mpirun -n 2"
ok = ok and "sphericity" in two["steps"][-1]["metrics"] and "sphericity" in two["initial_metrics"]
print("run's 2-rank cell: status %s, ranks %s, max distance to the 1-rank cell at step 3 %.3g, "
      "peak scope %r" % (two["status"], two["distribution"]["ranks"], d["max"], two["peak_memory_scope"]))
sys.exit(0 if ok else 1)
PY
[ ! -e "$work/ranks/.mpi" ] || [ -z "$(ls -A "$work/ranks/.mpi")" ] || fail "the scratch folder of the 2-rank cell was left"
echo "mpi_flow: ok"
