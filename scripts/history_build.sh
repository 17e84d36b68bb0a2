#!/usr/bin/env bash
# `history_build.sh TARGET...`: the executables TARGET... (Release) of the commit checked out in
# the current folder (a history worktree), for the history runners (scripts/history_runner.sh,
# scripts/history_micro_runner.sh). Prints the folder that holds them,
# $MCFBENCH_HISTORY_BUILDS/<commit> (default ~/.cache/mcfbench-history/<commit>), building those
# not there yet: a commit is built once however often it is measured.
# The compilation happens in one build slot per repository, kept beside those folders
# ($builds/slot-<repository hash>/: a git worktree of the repository and its build folder), moved
# to each commit with `git checkout`, which rewrites only the files that differ: ninja then
# recompiles only what those files touch, so a run over consecutive commits costs a few
# compilations per commit instead of a whole build (a commit's own worktree lives in a new
# temporary folder every time, which would defeat both ninja and ccache). The slot is locked while
# in use, so two history runs on one machine take turns. A slot whose folder is deleted is
# forgotten by `git worktree prune`. $MCFBENCH_JOBS: parallel jobs (default: the cores).
set -euo pipefail
commit=$(git rev-parse HEAD)
builds=$(realpath -m "${MCFBENCH_HISTORY_BUILDS:-${XDG_CACHE_HOME:-$HOME/.cache}/mcfbench-history}")
build=$builds/$commit
missing=()
for t in "$@"; do [ -x "$build/$t" ] || missing+=("$t"); done
if [ ${#missing[@]} = 0 ]; then
  echo "$build"
  exit 0
fi
set -- "${missing[@]}"
common=$(cd "$(git rev-parse --git-common-dir)" && pwd)
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
echo "$build"
