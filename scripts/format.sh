#!/usr/bin/env bash
# Formats the C++ sources (*.h, *.cpp tracked by git, and new ones git does not ignore) with the
# repository's .clang-format, so a file not yet added is formatted before its first commit.
#   scripts/format.sh           rewrites them in place
#   scripts/format.sh --check   changes nothing: lists the files that are not formatted, exits 1
# Exits 77 when clang-format is missing (scripts/setup.sh installs it): the `format` test then
# reports itself skipped, not passed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
check=0
case "${1:-}" in
  --check) check=1 ;;
  "") ;;
  *) echo "usage: scripts/format.sh [--check]" >&2; exit 2 ;;
esac
if ! command -v clang-format >/dev/null 2>&1; then
  echo "format.sh: clang-format not found (scripts/setup.sh installs it)" >&2
  exit 77
fi
cd "$root"
mapfile -t files < <(git ls-files --cached --others --exclude-standard -- '*.h' '*.cpp')
[ ${#files[@]} -gt 0 ] || { echo "format.sh: no tracked C++ sources under $root" >&2; exit 1; }
if [ $check = 0 ]; then
  clang-format -i -- "${files[@]}"
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  clang-format --dry-run --Werror -- "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "not formatted (run scripts/format.sh):"
  printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "format ok (${#files[@]} files)"
