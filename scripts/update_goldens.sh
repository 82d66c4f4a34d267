#!/usr/bin/env bash
# Regenerates the golden images in tests/golden/ on purpose (after an intended change of the
# simulation or the rendering): builds clothsim, runs every command listed in
# tests/golden/goldens.txt (the same commands as tests/app/golden_test.cpp) in a temporary folder
# and copies the compared frames into tests/golden/. Look at the images before committing them.
# Usage: scripts/update_goldens.sh
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/release/CMakeCache.txt ] || cmake --preset release >/dev/null
cmake --build --preset release --target clothsim
binary=build/release/clothsim
manifest=tests/golden/goldens.txt

tmp="$(mktemp -d "${TMPDIR:-/tmp}/clothsim_update_goldens_XXXXXX")"
trap 'rm -rf "$tmp"' EXIT

count=0
while read -r golden scene rendered options; do
  case "$golden" in ''|'#'*) continue ;; esac
  if [ -z "$rendered" ]; then
    echo "update_goldens: $manifest: expected GOLDEN.png SCENE RENDERED OPTIONS... (got \"$golden $scene\")" >&2
    exit 1
  fi
  out="$tmp/${golden%.png}"
  read -ra words <<<"$options"  # plain words, no quoting
  command=("$binary" "$scene" --out "$out" "${words[@]}")
  echo "update_goldens: ${command[*]}"
  start=$SECONDS
  if ! "${command[@]}" >"$tmp/log.txt" 2>&1; then
    cat "$tmp/log.txt" >&2
    echo "update_goldens: the run for $golden failed" >&2
    exit 1
  fi
  if [ ! -f "$out/$rendered" ]; then
    echo "update_goldens: the run for $golden wrote no $rendered" >&2
    exit 1
  fi
  target="tests/golden/$golden"
  if [ ! -f "$target" ]; then status=new
  elif cmp -s "$out/$rendered" "$target"; then status=unchanged
  else status=changed
  fi
  cp "$out/$rendered" "$target"
  echo "update_goldens: wrote $target ($status; $rendered, $((SECONDS - start)) s)"
  count=$((count + 1))
done <"$manifest"
echo "update_goldens: $count goldens in tests/golden/"
