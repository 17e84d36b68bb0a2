#!/usr/bin/env bash
# The installed library from a program's side: `cmake --install` of the build into a scratch
# prefix, then examples/consumer, a CMake project of its own (none of the build's flags, no
# -march=native), configured against that prefix, built and run. It must find the package, its
# headers (and no internal header: only include/mcfbench/ is installed) and the library, and its
# flow of the unit sphere must stop where the semi-implicit recursion r' = r^3 / (r^2 + 2 dt)
# first falls below radius 0.5. The installed Python module must import from its folder.
# usage: test_install.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log"
extra=$(find "$tmp/prefix/include" -name '*.h' ! -path "$tmp/prefix/include/mcfbench/*")
if [ -n "$extra" ]; then
  echo "installed headers outside include/mcfbench/: $extra"
  exit 1
fi
cmake -S "$src/examples/consumer" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DCMAKE_BUILD_TYPE=Release >"$tmp/configure.log" || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/consumer" >"$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
out=$("$tmp/consumer/consumer")
echo "consumer: $out"
/usr/bin/python3 - "$out" <<'PY'
import sys
steps, radius = int(sys.argv[1].split()[0]), float(sys.argv[1].split()[-1])
r, n, dt = 1.0, 0, 1e-2
while r >= 0.5:
    r, n = r**3 / (r**2 + 2 * dt), n + 1
# The discrete sphere follows the recursion to its spatial error (far below a step's change of
# about 2 dt / r = 0.04 near r = 0.5), so the stop falls on the same step, or on its neighbour
# where the recursion ends within that error of 0.5.
ok = abs(steps - n) <= 1 and 0.45 < radius < 0.5
print("recursion: %d steps, radius %.6f -> %s" % (n, r, "ok" if ok else "MISMATCH"))
sys.exit(0 if ok else 1)
PY
module_dir=$(dirname "$(find "$tmp/prefix" -name 'mcfbench.cpython-*.so' | head -1)")
if [ "$module_dir" != . ]; then
  (cd "$tmp" && PYTHONPATH="$module_dir" /usr/bin/python3 -c \
    "import mcfbench, os; assert mcfbench.__file__.startswith('$tmp/prefix'), mcfbench.__file__; print('installed module:', os.path.relpath(mcfbench.__file__, '$tmp/prefix'))")
fi
echo "install ok"
