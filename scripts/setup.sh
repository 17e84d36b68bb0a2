#!/usr/bin/env bash
# Installs the Debian packages mcfbench needs, only those that are missing, and extracts the
# real-model archive of libcgal-demo without pulling in its Qt dependencies.
# Does nothing (and needs no network) when everything is already present.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev
  libsuitesparse-dev libopenblas-dev     # CHOLMOD on OpenBLAS (the reference BLAS is 3-4x slower)
  libtbb-dev
  libopenmesh-dev
  nlohmann-json3-dev
  libcli11-dev
  libpetsc-real-dev openmpi-bin          # --solver petsc: PETSc's KSP, GAMG, hypre's BoomerAMG (docs/petsc.md)
  libbenchmark-dev
  libgtest-dev
  clang-format                           # scripts/format.sh and the `format` test
  clang libclang-rt-dev                  # the fuzz targets (libFuzzer), built and run by the suite
  python3-matplotlib python3-numpy
  pybind11-dev python3-dev               # the Python module `mcfbench` (docs/python.md)
  python3-pytest python3-pandas          # its tests; mcfbench.results' DataFrame
  python3-scipy                          # mcfbench.matrices as scipy.sparse, the tests' Python solver
  slurmctld slurmd slurm-client munge    # the `slurm_live` test starts a single-node Slurm of its own
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing missing Debian packages: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# Real meshes: libcgal-demo's data.tar.gz. Installing the package pulls in Qt, so download the
# .deb and unpack it into a cache instead (docs/flow.md "Mesh specs").
cache="${MCFBENCH_CACHE:-$HOME/.cache/mcfbench}"
if ! bash "$(dirname "$0")/cgal_archive.sh" >/dev/null; then
  echo "setup: fetching libcgal-demo's data.tar.gz into $cache/cgal-demo" >&2
  mkdir -p "$cache/cgal-demo"
  tmp=$(mktemp -d)
  ( cd "$tmp" && { apt-get download libcgal-demo >/dev/null 2>&1 || { $SUDO apt-get update -qq && apt-get download libcgal-demo >/dev/null; }; } \
      && dpkg -x libcgal-demo_*.deb "$cache/cgal-demo" )
  rm -rf "$tmp"
fi
