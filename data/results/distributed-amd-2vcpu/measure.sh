#!/bin/bash
# The distributed flow against one process (docs/benchmarks.md, "Across MPI ranks"): step time
# (5 alternations), contraction and peak memory per rank. Usage: measure.sh [OUT] (default
# out/distributed); MCFBENCH names the binary. About 4 minutes on 2 cores.
set -u
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
B=${MCFBENCH:-build/mcfbench}
out=${1:-out/distributed}; mkdir -p $out
# 1. step time, alternating, 5 reps
A="--mesh cgal:armadillo@faces=832000 --flow cmcf --normalize-area --dt 1e-3 --steps 8 --solver multigrid --cycle V --smooth 2 --cycles 2"
for rep in 1 2 3 4 5; do
  $B flow $A --threads 2 --out $out/step-one-$rep > /dev/null 2>&1
  mpirun -n 2 $B flow $A --threads 1 --out $out/step-two-$rep > /dev/null 2>&1
done
# 2. contraction to 1e-10, 8 steps
C="--mesh cgal:armadillo@faces=832000 --flow cmcf --normalize-area --dt 1e-3 --steps 8 --solver multigrid --cycle V --smooth 2 --tolerance 1e-10 --cycles 100"
$B flow $C --threads 2 --out $out/contraction-one > /dev/null 2>&1
mpirun -n 2 $B flow $C --threads 1 --out $out/contraction-two > /dev/null 2>&1
# 3. memory, 3.2M faces, 1, 2 and 4 ranks
M="--mesh sphere:vertices=1600000 --solver multigrid --cycle V --smooth 2 --cycles 2 --threads 1 --dt 1e-3 --steps 2"
$B flow $M --out $out/mem-1 > /dev/null 2>&1
mpirun --oversubscribe -n 4 $B flow $M --out $out/mem-4 > /dev/null 2>&1
mpirun --oversubscribe -n 2 $B flow $M --out $out/mem-2 > /dev/null 2>&1
# 4. memory with PETSc's CG + GAMG, the same mesh
P="--mesh sphere:vertices=1600000 --solver petsc --threads 1 --dt 1e-3 --steps 2"
$B flow $P --out $out/mem-petsc-1 > /dev/null 2>&1
mpirun --oversubscribe -n 4 $B flow $P --out $out/mem-petsc-4 > /dev/null 2>&1
mpirun --oversubscribe -n 2 $B flow $P --out $out/mem-petsc-2 > /dev/null 2>&1
