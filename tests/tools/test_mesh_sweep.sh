#!/usr/bin/env bash
# The mesh sweep (scripts/sweep_meshes.sh) on a bounded subset of the CGAL data archive: one mesh
# of each kind that used to be refused or reported singular, beside a few that always flowed.
# Every run must be classified (no singular flow, no crash, no unnamed refusal), and the kinds
# must come out as docs/flow.md says. Skipped (77) where the archive is missing.
#   tests/tools/test_mesh_sweep.sh MCFBENCH_BINARY
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$1
archive=$(bash "$root/scripts/cgal_archive.sh") || archive=
if [ -z "$archive" ]; then
  echo "libcgal-demo's data.tar.gz not found (scripts/setup.sh): skipped"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
subset=(triangle quad mesh_with_colors tet-shuffled cube-shuffled oblong-shuffled degtri_sliding
        mpi tetrahedron cube open_cube hedra_open)
members=()
for m in "${subset[@]}"; do members+=("data/meshes/$m.off"); done
tar -xzf "$archive" -C "$tmp" "${members[@]}"
files=()
for m in "${subset[@]}"; do files+=("$tmp/data/meshes/$m.off"); done

rc=0
MCFBENCH_BINARY=$bin bash "$root/scripts/sweep_meshes.sh" --out "$tmp/sweep" "${files[@]}" || rc=$?
if [ "$rc" -ne 0 ]; then
  echo "FAIL: the sweep found unexplained runs (exit $rc)"
  exit 1
fi

table=$tmp/sweep/sweep.tsv
fail=0
# expect FILE BASIS OUTCOME REASON: the row of that run says so.
expect() {
  local got
  got=$(awk -F'\t' -v f="$1" -v b="$2" '$1 == f && $2 == b { print $3 "|" $4 }' "$table")
  if [ "$got" != "$3|$4" ]; then
    echo "FAIL: $1 [$2]: expected '$3|$4', got '$got'"
    fail=1
  fi
}
for basis in hat+cholmod hat+multigrid; do
  expect triangle.off "$basis" flowed "nothing free to move (mesh unchanged)"
  expect quad.off "$basis" flowed "nothing free to move (mesh unchanged)"
  expect mesh_with_colors.off "$basis" flowed "nothing free to move (mesh unchanged)"
  expect degtri_sliding.off "$basis" refused "degenerate face"
  expect mpi.off "$basis" refused "degenerate face"
done
for basis in hat+cholmod hat+multigrid octree; do
  expect tet-shuffled.off "$basis" flowed reoriented
  expect cube-shuffled.off "$basis" flowed reoriented
  expect oblong-shuffled.off "$basis" flowed reoriented
  expect tetrahedron.off "$basis" flowed ""
done
expect mpi.off octree flowed "degenerate faces kept"
if grep -q $'\tsingular\t' "$table"; then
  echo "FAIL: a singular flow"
  fail=1
fi
if [ "$fail" -ne 0 ]; then
  cat "$table"
  exit 1
fi
echo "mesh sweep subset: every run as expected"
