#!/usr/bin/env bash
# The default runner of scripts/history.sh: `history_runner.sh CONFIG OUT`, run in a git
# worktree checked out at the commit to measure. Takes that commit's mcfbench (Release) from the
# build cache, building it there first if need be (scripts/history_build.sh), then runs CONFIG's
# --quick variant with $MCFBENCH_HISTORY_REPETITIONS repetitions (default 5) into OUT. The config is the caller's file, not the commit's, so every commit runs the same
# cells.
set -euo pipefail
config=$1
out=$2
reps=${MCFBENCH_HISTORY_REPETITIONS:-5}
build=$(bash "$(dirname "$0")/history_build.sh" mcfbench)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Same cells as the config's quick variant, with the repetitions asked for.
/usr/bin/python3 - "$config" "$reps" "$tmp/$(basename "$config")" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c.setdefault("quick", {})["repetitions"] = int(sys.argv[2])
json.dump(c, open(sys.argv[3], "w"))
PY
"$build/mcfbench" run "$tmp/$(basename "$config")" --quick --out "$out" >&2
