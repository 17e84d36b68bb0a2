#!/usr/bin/env bash
# One flow's PETSc solves across two MPI ranks (docs/petsc.md, "Across MPI ranks"):
# `mpirun -n 2 mcfbench flow ... --solver petsc` writes one result whose final surface matches the
# same flow run without mpirun to 1e-8 of the bounding box's diagonal, records two ranks, and
# leaves no second output, and holds about half of the matrix and of GAMG's hierarchy on each rank; a
# solver other than petsc under mpirun is refused, writing nothing; a flow asking for 2 ranks without
# them is refused; a study cell with mpi_ranks 2 runs under mpirun started by `mcfbench run`.
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
flow=(flow --mesh sphere:vertices=3000 --solver petsc --threads 1 --dt 1e-3 --steps 3)
if ! "$mcfbench" "${flow[@]}" --out "$work/serial" 2>"$work/serial.log"; then
  if grep -q "built without PETSc" "$work/serial.log"; then echo "skipped: built without PETSc"; exit 77; fi
  cat "$work/serial.log"; echo "FAIL: the serial flow failed"; exit 1
fi
fail() { echo "FAIL: $*"; exit 1; }
mpirun -n 2 "$mcfbench" "${flow[@]}" --out "$work/mpi" >"$work/mpi.log" 2>&1 ||
  { cat "$work/mpi.log"; fail "mpirun -n 2 failed"; }
[ -f "$work/mpi/result.json" ] || fail "no result.json from the MPI run"
[ "$(ls "$work" | sort | tr '\n' ' ')" = "mpi mpi.log serial serial.log " ] || fail "other output: $(ls "$work")"
"$py" - "$work/serial" "$work/mpi" <<'PY' || exit 1
import json, sys
import numpy as np
def read(p):
    d = open(p + "/final.ply", "rb").read()
    h = d.index(b"end_header\n") + len(b"end_header\n")
    n = int([l for l in d[:h].decode().split("\n") if l.startswith("element vertex")][0].split()[-1])
    return np.frombuffer(d[h:h + 24 * n], dtype="<f8").reshape(n, 3)
a, b = read(sys.argv[1]), read(sys.argv[2])
diag = np.linalg.norm(a.max(0) - a.min(0))
dev = np.abs(a - b).max() / diag
r = json.load(open(sys.argv[2] + "/result.json"))
one = json.load(open(sys.argv[1] + "/result.json"))
ranks = r["solver_settings"]["ranks"]
ok = dev < 1e-8 and ranks == "2" and r["status"] == "ok"
# The matrix's storage on one rank: a double and a 32- or 64-bit index per entry, an offset per
# row. The hat basis on a closed genus-0 mesh has a row per vertex and an entry per vertex and per
# edge end, n + 2 (3n - 6) (Euler). Two ranks hold about half of it each.
n = one["system"]["dimension"]
nnz = 7 * n - 12
serial_bytes = int(one["solver_settings"]["matrix_bytes_per_rank"])
layouts = [nnz * (8 + w) + (n + 1) * w for w in (4, 8)]
ok = ok and serial_bytes in layouts
ratio = int(r["solver_settings"]["matrix_bytes_per_rank"]) / serial_bytes
ok = ok and 0.45 <= ratio <= 0.6
pc_one = int(one["solver_settings"]["preconditioner_bytes_per_rank"])
pc_ratio = int(r["solver_settings"]["preconditioner_bytes_per_rank"]) / pc_one
ok = ok and pc_one > 0 and pc_ratio <= 0.75
print("matrix storage per rank: %d bytes on one rank (layouts %s), 2 ranks %.3f of it; "
      "GAMG's hierarchy per rank, 2 ranks %.3f of one's" % (serial_bytes, layouts, ratio, pc_ratio))
for step in r["steps"]:
    ok = ok and step["solver"]["status"] == "converged" and step["solver"]["relative_residual"] <= 1e-10
print("mpi vs serial: %.3g of the diagonal, ranks %s, status %s" % (dev, ranks, r["status"]))
sys.exit(0 if ok else 1)
PY
mpirun -n 2 "$mcfbench" flow --mesh sphere:vertices=500 --threads 1 --steps 1 --out "$work/cholmod" \
  >"$work/cholmod.log" 2>&1 && fail "cholmod under mpirun -n 2 was not refused"
grep -q 'only "petsc" runs across the 2 ranks' "$work/cholmod.log" || fail "no refusal message: $(cat "$work/cholmod.log")"
[ ! -e "$work/cholmod" ] || fail "the refused run wrote $work/cholmod"
# A flow that asks for 2 ranks is refused when not started on them, writing nothing.
"$mcfbench" "${flow[@]}" --mpi-ranks 2 --out "$work/unranked" >"$work/unranked.log" 2>&1 &&
  fail "--mpi-ranks 2 without mpirun was not refused"
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
ok = sorted(cells) == [1, 2] and two["status"] == "ok" and two["solver_settings"]["ranks"] == "2"
d = two["reference_distance"][0]
ok = ok and d["step"] == 3 and d["max"] < 1e-8
ok = ok and two["peak_memory_scope"] == "rank 0 of mpirun -n 2"
ok = ok and "sphericity" in two["steps"][-1]["metrics"] and "sphericity" in two["initial_metrics"]
print("run's 2-rank cell: status %s, ranks %s, max distance to the 1-rank cell at step 3 %.3g, "
      "peak scope %r" % (two["status"], two["solver_settings"]["ranks"], d["max"], two["peak_memory_scope"]))
sys.exit(0 if ok else 1)
PY
[ ! -e "$work/ranks/.mpi" ] || [ -z "$(ls -A "$work/ranks/.mpi")" ] || fail "the scratch folder of the 2-rank cell was left"
echo "mpi_flow: ok"
