#!/usr/bin/env bash
# `hat_step_ab.sh OLD NEW OUT [REPS]`: two builds of mcfbench (OLD, NEW: paths to the executables,
# e.g. a commit's from scripts/history_build.sh) timed on the same flows, interleaved: per
# repetition, per flow (cMCF at dt 1e-3 with unit area, MCF at dt 1e-5, the armadillo at 832k
# faces, 8 steps, 2 threads), OLD then NEW, each with CHOLMOD and with two V(2,2)-cycles a step.
# Prints one line a flow run: repetition, flow, build, solver, the median step (steps 2 on, s), the
# set-up (s) and whether the run was contended; each run's result.json stays in OUT. Ratios to
# CHOLMOD are taken within one build and repetition (docs/benchmarks.md, "The hat step").
set -euo pipefail
OLD=$1 NEW=$2 OUT=$3 REPS=${4:-3}
mkdir -p "$OUT"
mesh=cgal:armadillo@faces=832000
for rep in $(seq 1 "$REPS"); do
  for flow in cmcf mcf; do
    if [ $flow = cmcf ]; then fl=(--flow cmcf --normalize-area --dt 1e-3); else fl=(--flow mcf --dt 1e-5); fi
    for build in old new; do
      exe=$OLD
      [ $build = new ] && exe=$NEW
      for solver in cholmod mg; do
        if [ $solver = cholmod ]; then so=(--solver cholmod); else so=(--solver multigrid --cycle V --cycles 2 --smooth 2); fi
        d=$OUT/$rep-$flow-$build-$solver
        rm -rf "$d"
        "$exe" flow --mesh $mesh "${fl[@]}" "${so[@]}" --steps 8 --threads 2 --out "$d" >/dev/null 2>&1
        echo "$rep $flow $build $solver $(/usr/bin/python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print(r['timing']['step_median_seconds'], r['timing']['setup_seconds'], r['contention'].get('contended'))" "$d/result.json")"
      done
    done
  done
done
