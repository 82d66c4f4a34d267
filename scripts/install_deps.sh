#!/usr/bin/env bash
# Installs clothsim's build and test dependencies from Debian 12 packages only.
# Usage: scripts/install_deps.sh   (runs apt-get through sudo when not root)
set -euo pipefail
packages=(
  cmake g++ make pkg-config
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libpng-dev libosmesa6-dev libembree-dev libtbb-dev
  libgtest-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libcgal-dev
  python3-minimal python3-matplotlib python3-jsonschema
  pybind11-dev python3-dev python3-numpy python3-pytest  # the Python module (python/, docs/python.md) and its tests
  parallel  # clothsim study ... -j N (the local executor, docs/cluster.md)
  clang libclang-rt-14-dev llvm  # scripts/sanitize.sh: clang 14, its sanitizer and libFuzzer run-times, llvm-symbolizer
)
# Optional: PETSc 3.18 (with hypre's BoomerAMG and ML) for bench/multilevel_bench's comparison with
# those libraries' algebraic multigrid (docs/performance.md, "Multilevel preconditioners"); about
# 110 packages with MPI, so only with CLOTHSIM_PETSC=1. Without it multilevel_bench builds without
# the petsc: candidates.
if [ "${CLOTHSIM_PETSC:-0}" = 1 ]; then
  packages+=(libpetsc-real-dev)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "install_deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
