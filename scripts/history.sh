#!/usr/bin/env bash
# Performance history over commits: run, add, detect, bisect, ab, publish
# (reports/perf_history.py; `scripts/history.sh COMMAND --help` for each; docs/history.md).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exec /usr/bin/python3 "$root/reports/perf_history.py" "$@"
