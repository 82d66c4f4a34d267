#!/usr/bin/env bash
# README command 2: install dependencies, build (Release) and run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
