#!/usr/bin/env bash
# Fails if a layer, or its tests (tests/LAYER), includes a header of a layer above it (docs/design.md
# "Layers"). core is the bottom layer: it includes no other layer, and every layer may include it.
root=${1:-$(dirname "$0")/..}
order=(core datasets bases solvers flows bench benchmarks tools fuzz)
# solvers sits beside bases (neither may include the other), and beside datasets; the
# micro-benchmarks (benchmarks/), the executable (tools/) and the fuzz targets (fuzz/) sit beside
# each other on top.
declare -A forbidden=(
  [core]="datasets bases solvers flows bench benchmarks tools"
  [datasets]="bases solvers flows bench benchmarks tools"
  [bases]="solvers flows bench benchmarks tools"
  [solvers]="datasets bases flows bench benchmarks tools"
  [flows]="bench benchmarks tools"
  [bench]="benchmarks tools"
  [benchmarks]="tools"
  [tools]="benchmarks fuzz"
  [fuzz]="benchmarks tools"
)
bad=0
for layer in "${order[@]}"; do
  for up in ${forbidden[$layer]}; do
    if hits=$(grep -rnE "#include +\"(\.\./)*$up/" "$root/$layer" "$root/tests/$layer" \
                --include='*.h' --include='*.cpp' 2>/dev/null); then
      echo "layering violation: $layer includes $up:"; echo "$hits"; bad=1
    fi
  done
done
[ $bad = 0 ] && echo "layering ok"
exit $bad
