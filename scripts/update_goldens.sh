#!/usr/bin/env bash
# Regenerates the golden images in tests/golden/ on purpose (after an intended change of the
# simulation or the rendering): builds clothsim and runs
#   clothsim golden update tests/golden/goldens.txt
# which runs every line of the manifest in a temporary folder (the same commands as
# `clothsim golden check`, which tests/app/golden_test.cpp runs) and, only if every run succeeds,
# rewrites the goldens whose bytes changed. Look at the images before committing them.
# Usage: scripts/update_goldens.sh
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/release/CMakeCache.txt ] || cmake --preset release >/dev/null
cmake --build --preset release --target clothsim
exec build/release/clothsim golden update tests/golden/goldens.txt
