#!/usr/bin/env bash
# README command 1: install dependencies, build (Release) and run the default scene.
# Usage: scripts/demo.sh [SCENE.json] [clothsim options...]   (default: scenes/sleeve_twist.json)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install_deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target clothsim
scene="${1:-scenes/sleeve_twist.json}"
[ $# -gt 0 ] && shift
build/release/clothsim "$scene" "$@"
