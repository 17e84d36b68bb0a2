#!/usr/bin/env bash
# The main job on a small default: set-up, build, then a demo experiment that writes results
# (and, once the report layer exists, plots) under out/demo.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
out=${1:-$root/out/demo}
bash "$root/scripts/build.sh"
mcf="$build/mcfbench"
"$mcf" flow --mesh icosphere:level=4 --flow mcf --basis hat --solver cholmod --dt 1e-3 --steps 50 --out "$out/mcf_sphere"
"$mcf" flow --mesh icosphere:level=4 --flow cmcf --basis hat --solver pcg --preconditioner ichol --dt 1e-3 --steps 50 --out "$out/cmcf_sphere"
"$mcf" flow --mesh cgal:bunny00 --flow cmcf --basis hat --solver cholmod --normalize-area --dt 1e-3 --steps 20 --save-every 5 --out "$out/cmcf_bunny"
echo "demo results in $out" >&2
