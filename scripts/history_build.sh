#!/usr/bin/env bash
# `history_build.sh BUILD TARGET...`: builds TARGETs (Release) of the commit checked out in the
# current folder (a history worktree) and copies the executables into the folder BUILD (beside
# any others there), for the
# history runners (scripts/history_runner.sh, scripts/history_micro_runner.sh).
# The compilation happens in one build slot per repository, kept beside BUILD's parent
# ($builds/slot-<repository hash>/: a git worktree of the repository and its build folder), moved
# to each commit with `git checkout`, which rewrites only the files that differ: ninja then
# recompiles only what those files touch, so a run over consecutive commits costs a few
# compilations per commit instead of a whole build (a commit's own worktree lives in a new
# temporary folder every time, which would defeat both ninja and ccache). The slot is locked while
# in use, so two history runs on one machine take turns. A slot whose folder is deleted is
# forgotten by `git worktree prune`. $MCFBENCH_JOBS: parallel jobs (default: the cores).
set -euo pipefail
build=$1
shift
commit=$(git rev-parse HEAD)
common=$(cd "$(git rev-parse --git-common-dir)" && pwd)
builds=$(dirname "$(realpath -m "$build")")
slot=$builds/slot-$(printf '%s' "$common" | sha1sum | cut -c1-12)
mkdir -p "$builds"
exec 9>"$slot.lock"
flock 9
if ! git -C "$slot/src" rev-parse --git-dir >/dev/null 2>&1; then
  rm -rf "$slot"
  git --git-dir="$common" worktree prune
  git --git-dir="$common" worktree add --detach --force "$slot/src" "$commit" >&2
else
  git -C "$slot/src" checkout --detach --force --quiet "$commit"
  git -C "$slot/src" clean -fdq
fi
generator=()
if command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi
if [ ! -f "$slot/build/CMakeCache.txt" ]; then
  cmake -S "$slot/src" -B "$slot/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >&2
fi
cmake --build "$slot/build" --parallel "${MCFBENCH_JOBS:-$(nproc)}" --target "$@" >&2
# The executables are linked statically against the project's own libraries: copied, they run
# after the slot has moved on. Each lands whole or not at all (a runner takes a present one).
mkdir -p "$build"
for t in "$@"; do
  cp "$slot/build/$t" "$build/$t.tmp"
  mv "$build/$t.tmp" "$build/$t"
done
