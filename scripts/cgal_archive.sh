#!/usr/bin/env bash
# Prints the path of libcgal-demo's data.tar.gz (the real meshes): the installed package's, or the
# copy scripts/setup.sh downloads into $MCFBENCH_CACHE (default ~/.cache/mcfbench). Exits 1,
# printing nothing, where neither is there. The same two places as datasets/catalogue.cpp.
cache=${MCFBENCH_CACHE:-${HOME:-/tmp}/.cache/mcfbench}
for a in /usr/share/doc/libcgal-dev/data.tar.gz "$cache/cgal-demo/usr/share/doc/libcgal-dev/data.tar.gz"; do
  if [ -f "$a" ]; then echo "$a"; exit 0; fi
done
exit 1
