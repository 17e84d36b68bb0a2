#!/usr/bin/env bash
# The main job on a small default: set-up, build, then the quick variant of every study of
# bench/configs (minutes on 2 cores) and the report with every figure and table:
#   out/demo/results/<study>/*.json   out/demo/report/index.md (+ PNG, Markdown)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh"
exec bash "$root/scripts/run_studies.sh" --quick --out "${1:-$root/out/demo}"
