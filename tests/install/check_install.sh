#!/bin/sh
# `cmake --install` gives a clothsim that runs without its source tree: installs the build into a
# temporary prefix, moves the prefix elsewhere (it must be relocatable), and from a folder outside
# the source tree runs an installed scene and the fold study, whose scenes and plotting script
# must come from the installed share/clothsim/ (checked by swapping the installed plotting
# script for a stand-in that marks its output, and by breaking an installed scene).
# Usage: check_install.sh CMAKE BUILD_DIR WORK_DIR
set -eu
cmake=$1
build=$2
work=$3

rm -rf "$work"
mkdir -p "$work"
"$cmake" --install "$build" --prefix "$work/prefix" >"$work/install.log"

for f in bin/clothsim share/clothsim/scripts/plot_folds.py share/clothsim/scripts/montage.py \
         share/clothsim/scenes/sleeve_twist.json share/clothsim/scenes/meshes/cusick_disc_r015.obj \
         share/doc/clothsim/README.md share/doc/clothsim/docs/formulas.md; do
  [ -e "$work/prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done

# Relocate: only the moved prefix is used from here on.
mv "$work/prefix" "$work/moved"
prefix=$work/moved
clothsim=$prefix/bin/clothsim
mkdir -p "$work/run"
cd "$work/run"

"$clothsim" --version
"$clothsim" "$prefix/share/clothsim/scenes/plate_ss.json" --no-render --out out
[ -s out/plate_ss/result.json ] || { echo "no static result"; exit 1; }
"$clothsim" "$prefix/share/clothsim/scenes/sleeve_twist.json" --no-render --frames 2 --out out
[ -s out/sleeve_twist/probes.csv ] || { echo "no dynamic result"; exit 1; }
# A scene that references a mesh file next to it.
"$clothsim" "$prefix/share/clothsim/scenes/cusick_drape.json" --no-render --frames 1 --out out
[ -s out/cusick_drape/probes.csv ] || { echo "no cusick_drape result"; exit 1; }

# The fold study reads its scenes from the installed share/clothsim/scenes and runs the installed
# share/clothsim/scripts/plot_folds.py: a stand-in script writes a marker instead of the plot.
cat >"$prefix/share/clothsim/scripts/plot_folds.py" <<'PY'
import sys
with open(sys.argv[2], "w") as f:
    f.write("drawn by the installed plot_folds.py\n")
PY
"$clothsim" study folds --quick --cases twist --out out
grep -q "drawn by the installed plot_folds.py" out/study_folds/folds_vs_vertices.png ||
  { echo "the fold study did not run the installed plotting script"; exit 1; }
[ -s out/study_folds/results.csv ] || { echo "no fold study results"; exit 1; }

# And its scenes come from share/clothsim/scenes: a broken installed scene is the one reported.
echo "{" >"$prefix/share/clothsim/scenes/sleeve_twist.json"
if "$clothsim" study folds --quick --cases twist --out out2 2>"$work/broken.err"; then
  echo "the fold study did not read the installed (broken) sleeve_twist.json"; exit 1
fi
grep -F "$prefix/share/clothsim/scenes/sleeve_twist.json" "$work/broken.err" ||
  { echo "the error does not name the installed scene:"; cat "$work/broken.err"; exit 1; }
echo "installed clothsim works without the source tree"
