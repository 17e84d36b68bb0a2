#!/usr/bin/env bash
# ctest `clang_rejects_vexing_parse`: clang, with the project's -Werror=vexing-parse, refuses the
# old shape of vexing_parse.cpp and compiles the fixed one, and GCC compiles the fixed one too; so
# the clang build in CI (scripts/test.sh builds the fuzz targets with clang) fails on a
# declaration that only GCC reads as intended.
#   check_vexing_parse.sh CLANG GCC
set -uo pipefail
clang=$1 gcc=$2
here=$(cd "$(dirname "$0")" && pwd)
flags=(-std=c++20 -fsyntax-only -Wall -Werror=vexing-parse "$here/vexing_parse.cpp")
[ -x "$clang" ] || { echo "FAIL: $clang not found (scripts/setup.sh installs clang)"; exit 1; }
status=0
if "$clang" "${flags[@]}" 2>/dev/null; then
  echo "FAIL: clang compiled the old shape"; status=1
fi
"$clang" -DMCF_FIXED "${flags[@]}" || { echo "FAIL: clang refused the fixed shape"; status=1; }
"$gcc" -DMCF_FIXED "${flags[@]}" || { echo "FAIL: $gcc refused the fixed shape"; status=1; }
[ $status = 0 ] && echo "clang refuses the old shape; both compilers take the fixed one"
exit $status
