#!/usr/bin/env bash
# Peak resident memory against its estimate (config/memory_estimate.h) over the bases, solvers,
# depths and mesh sizes the estimate was fitted on: one one-step flow per row, written as CSV
# (spec, basis, tracking, solver, depth, vertices, unknowns, estimate and peak in MiB, ratio).
# Usage: benchmarks/peak_memory.sh [OUT.csv]   (default out/peak-memory.csv)
# Environment: MCFBENCH_BUILD (default build/). About 10 minutes on 2 cores; needs ~4 GiB.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=${MCFBENCH_BUILD:-$root/build}/mcfbench
out=${1:-$root/out/peak-memory.csv}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rows=$work/rows.csv
echo "spec,basis,tracking,solver,depth,vertices,unknowns,estimate_mib,peak_mib,estimate_over_peak" >"$rows"
flow() {
  rm -rf "$work/out"
  "$bin" flow --steps 1 --dt 1e-5 --max-memory none --out "$work/out" "$@" >/dev/null 2>&1
  /usr/bin/python3 - "$work/out/result.json" >>"$rows" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
c, m, e = r["config"], r["mesh"], r["memory_estimate"]
peak = r["peak_memory_bytes"] / 2**20
est = e["bytes"] / 2**20
octree = c["basis"] == "octree"
print(",".join(str(v) for v in [m["spec"], c["basis"], c["octree"]["tracking"] if octree else "",
      c["solver"]["name"], c["octree"]["depth"] if octree else "", m["vertices"],
      r["system"]["dimension"], round(est, 1), round(peak, 1), round(est / peak, 3)]))
PY
}
for mesh in cgal:armadillo cgal:armadillo@faces=200000 cgal:armadillo@faces=832000 sphere:vertices=100000; do
  echo "peak_memory.sh: $mesh" >&2
  flow --mesh "$mesh" --basis hat --solver cholmod
  flow --mesh "$mesh" --basis hat --solver pcg
  flow --mesh "$mesh" --basis hat --solver multigrid
  for depth in 6 7 8; do
    flow --mesh "$mesh" --basis octree --depth $depth --solver multigrid
    flow --mesh "$mesh" --basis octree --depth $depth --solver cholmod
    flow --mesh "$mesh" --basis octree --depth $depth --solver multigrid --tracking rebuilt
  done
done
flow --mesh cgal:armadillo@faces=832000 --basis octree --depth 9 --solver multigrid
flow --mesh cgal:armadillo@faces=832000 --basis octree --depth 9 --solver multigrid --tracking rebuilt
flow --mesh cgal:armadillo@faces=832000 --basis octree --depth 9 --solver cholmod
flow --mesh cgal:armadillo@faces=3300000 --basis hat --solver cholmod
flow --mesh cgal:elephant --basis octree --depth 8 --solver multigrid --stabilization none
flow --mesh cgal:elephant --basis octree --depth 8 --solver pcg --cubature 6
mkdir -p "$(dirname "$out")"
mv "$rows" "$out"
echo "peak_memory.sh: wrote $out" >&2
