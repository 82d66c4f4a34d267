#!/bin/sh
# scripts/check_frames.sh on a hand-made run: two frames of a cloth triangle 0.5 and 0.25 m above
# an obstacle triangle (no crossing; closest 0.25 m over both), then a third frame through it
# (a crossing: exit 1), and a folder without frames (exit 2).
# Usage: check_frames_test.sh SOURCE_DIR CHECK_INTERSECTIONS WORK_DIR
set -eu
src=$1 tool=$2 work=$3
rm -rf "$work" && mkdir -p "$work/run/frames" "$work/empty"
obstacle='v -1 -1 0\nv 2 -1 0\nv -1 2 0\nf 1 2 3\n'
printf "v 0 0 0.5\nv 1 0 0.5\nv 0 1 0.5\nf 1 2 3\n" > "$work/run/frames/mesh_0000.obj"
printf "v 0 0 0.25\nv 1 0 0.25\nv 0 1 0.25\nf 1 2 3\n" > "$work/run/frames/mesh_0001.obj"
printf "$obstacle" > "$work/run/frames/obstacles_0000.obj"
printf "$obstacle" > "$work/run/frames/obstacles_0001.obj"
out=$(bash "$src/scripts/check_frames.sh" "$work/run" "$tool")
echo "$out"
echo "$out" | grep -q "^frame 0000: self 0, obstacle 0, closest vertex 0.5 m$"
echo "$out" | grep -q "^frames: 2, with crossings: 0, closest vertex over all frames: 0.25 m$"
printf "v 0 0 -0.5\nv 1 0 0.5\nv 0 1 0.5\nf 1 2 3\n" > "$work/run/frames/mesh_0002.obj"
printf "$obstacle" > "$work/run/frames/obstacles_0002.obj"
if bash "$src/scripts/check_frames.sh" "$work/run" "$tool" > "$work/out.txt"; then echo "a crossing was not reported"; exit 1; fi
grep -q "^frames: 3, with crossings: 1," "$work/out.txt"
code=0
bash "$src/scripts/check_frames.sh" "$work/empty" "$tool" 2> "$work/err.txt" || code=$?
[ "$code" -eq 2 ] && grep -q "holds no mesh_NNNN.obj" "$work/err.txt"
echo "check_frames test passed"
