#!/usr/bin/env bash
# Runs studies of harness/configs (by default those harness/configs/studies.json marks run_by_default)
# and regenerates their report.
#   scripts/run_studies.sh [--quick] [--out DIR] [STUDY ...]
# Results: DIR/results/<study>/ (one JSON per cell; reruns skip finished cells),
# report: DIR/report/index.md, of every study under DIR/results (also those run earlier).
# Default DIR: out/studies (out/studies-quick with --quick).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${MCFBENCH_BUILD:-$root/build}
quick=""; out=""; studies=()
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick="--quick" ;;
    --out) out="$2"; shift ;;
    *) studies+=("$1") ;;
  esac
  shift
done
[ -n "$out" ] || out="$root/out/studies${quick:+-quick}"
if [ ${#studies[@]} -eq 0 ]; then
  # The studies harness/configs/studies.json marks run_by_default, in its order.
  listed=$(/usr/bin/python3 "$root/reports/study_manifest.py" --default)
  [ -n "$listed" ] || { echo "run_studies.sh: harness/configs/studies.json marks no study run_by_default" >&2; exit 1; }
  mapfile -t studies <<<"$listed"
fi
status=0
dirs=()
for s in "${studies[@]}"; do
  echo "== study $s ${quick}" >&2
  "$build/mcfbench" run "$root/harness/configs/$s.json" $quick --out "$out/results/$s" || status=1
done
# The report covers every study with results under DIR, not only those run now: running one
# study must not drop the others from DIR/report/index.md.
for d in "$out"/results/*/; do [ -d "$d" ] && dirs+=("${d%/}"); done
/usr/bin/python3 "$root/reports/make_report.py" "${dirs[@]}" "$out/report" --references "$root/harness/configs" || status=1
echo "report: $out/report/index.md" >&2
exit $status
