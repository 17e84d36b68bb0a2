#!/usr/bin/env bash
# The main job on a small default: set-up, build, then the quick variant of the studies
# harness/configs/studies.json marks run_by_default (scripts/run_studies.sh's default; minutes on 2
# cores) and the report with every figure and table:
#   out/demo/results/<study>/*.json   out/demo/report/index.md (+ PNG, Markdown)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
exec bash "$root/scripts/run_studies.sh" --quick --out "${1:-$root/out/demo}"
