#!/usr/bin/env bash
# scripts/history_build.sh on a scratch repository holding a two-file CMake project: the commit
# of each worktree is built in the repository's one build slot and its executable copied into
# the commit's folder; moving the slot to the next commit, which changed one file, recompiles
# that file only (the incremental build that keeps `history run` over many commits cheap), and
# each commit's copied executable is its own.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
repo=$work/repo
mkdir -p "$repo"
cd "$repo"
git init -q -b main
git config user.email t@t
git config user.name t
cat >CMakeLists.txt <<'CMAKE'
cmake_minimum_required(VERSION 3.20)
project(scratch CXX)
add_executable(answer main.cpp value.cpp)
CMAKE
printf 'int value();\n#include <cstdio>\nint main() { std::printf("%%d\\n", value()); }\n' >main.cpp
echo 'int value() { return 1; }' >value.cpp
git add -A && git commit -qm one
one=$(git rev-parse HEAD)
echo 'int value() { return 2; }' >value.cpp
git commit -qam two
two=$(git rev-parse HEAD)

builds=$work/builds
for c in "$one" "$two"; do
  git worktree add -q --detach "$work/wt-$c" "$c"
  folder=$(cd "$work/wt-$c" && MCFBENCH_HISTORY_BUILDS=$builds bash "$root/scripts/history_build.sh" answer 2>"$work/log-$c") ||
    { cat "$work/log-$c"; echo "FAIL: history_build.sh at $c"; exit 1; }
  [ "$folder" = "$builds/$c" ] || { echo "FAIL: history_build.sh printed $folder, not $builds/$c"; exit 1; }
  git worktree remove --force "$work/wt-$c"
done
fail=0
[ "$("$builds/$one/answer")" = 1 ] || { echo "FAIL: commit one's executable"; fail=1; }
[ "$("$builds/$two/answer")" = 2 ] || { echo "FAIL: commit two's executable"; fail=1; }
grep -q "main.cpp" "$work/log-$one" || { echo "FAIL: the first build compiled main.cpp"; fail=1; }
if grep -q "main.cpp" "$work/log-$two" || ! grep -q "value.cpp" "$work/log-$two"; then
  cat "$work/log-$two"
  echo "FAIL: the second commit should recompile value.cpp only"
  fail=1
fi
[ "$(ls -d "$builds"/slot-* | grep -vc '\.lock$')" = 1 ] || { echo "FAIL: one slot per repository"; fail=1; }
# A commit already built is not built again.
git worktree add -q --detach "$work/wt-again" "$one"
(cd "$work/wt-again" && MCFBENCH_HISTORY_BUILDS=$builds bash "$root/scripts/history_build.sh" answer >/dev/null 2>"$work/log-again")
git worktree remove --force "$work/wt-again"
[ ! -s "$work/log-again" ] || { cat "$work/log-again"; echo "FAIL: a built commit was built again"; fail=1; }
[ $fail = 0 ] && echo "ok: each commit's own executable; the second build recompiled the changed file only"
exit $fail
