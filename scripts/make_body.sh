#!/usr/bin/env bash
# Regenerates scenes/bodies/human_female.obj, the body mesh garments are dressed on, from the
# MakeHuman test model that Debian 12's assimp-testmodels package ships
# (/usr/share/assimp/models/Collada/human.zae, BSD-3-clause, see
# scenes/bodies/LICENSE.human_female.txt and docs/body.md).
#
# Steps: `assimp export human.zae human.obj -ptv -tri` (assimp-utils) in a temporary folder, then
# scripts/make_body.py keeps the largest closed component (drops the four open eye parts), welds
# exact duplicate positions, drops unused vertices, makes the normals face outward and writes the
# OBJ with 6-decimal positions and a header; scripts/check_body.py then checks the result.
# Installs nothing: it stops with the name of the Debian package that is missing.
#
# Usage: scripts/make_body.sh [OUT.obj]      (default scenes/bodies/human_female.obj)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-scenes/bodies/human_female.obj}"
model=/usr/share/assimp/models/Collada/human.zae
python=/usr/bin/python3

die() { echo "make_body: $*" >&2; exit 1; }
command -v assimp >/dev/null 2>&1 ||
  die "'assimp' not found: install the Debian package assimp-utils (apt-get install assimp-utils)"
[ -f "$model" ] ||
  die "$model not found: install the Debian package assimp-testmodels (apt-get install assimp-testmodels)"
[ -x "$python" ] || die "$python not found: install the Debian package python3"
"$python" -c "import numpy" 2>/dev/null ||
  die "numpy not importable by $python: install the Debian package python3-numpy"

version() { dpkg-query -W -f='${Version}' "$1" 2>/dev/null || echo "version unknown"; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if ! (cd "$tmp" && assimp export "$model" human.obj -ptv -tri) >"$tmp/assimp.log" 2>&1; then
  cat "$tmp/assimp.log" >&2
  die "assimp export failed"
fi
mkdir -p "$(dirname "$out")"
source_lines="Source: Debian 12 package assimp-testmodels $(version assimp-testmodels), file $model"
source_lines+="|  (a MakeHuman model: <author>www.makehumancommunity.org</author>), converted with"
source_lines+="|  'assimp export human.zae human.obj -ptv -tri' (assimp-utils $(version assimp-utils))."
"$python" scripts/make_body.py "$tmp/human.obj" "$out" \
  --source "$source_lines" --command "scripts/make_body.sh"
"$python" scripts/check_body.py "$out" >"$tmp/check.log" || { cat "$tmp/check.log" >&2; exit 1; }
echo "make_body: wrote $out ($(wc -c <"$out") bytes); $(tail -1 "$tmp/check.log")"
