#!/bin/bash
# Checks every OBJ frame of a run for crossings and reports how close the cloth came to the
# obstacles: check_intersections on frames/mesh_NNNN.obj against frames/obstacles_NNNN.obj (the
# obstacles as they were at that frame; none if the run has no obstacle).
#
# Usage: scripts/check_frames.sh RUN_DIR [CHECK_INTERSECTIONS]
#   RUN_DIR: a dynamic run's folder written with "output": {"obj": true} (it holds frames/).
#   CHECK_INTERSECTIONS: the tool (default build/release/tools/check_intersections).
# Prints one line per frame (self pairs, obstacle pairs, closest vertex distance [m]) and a
# summary: frames checked, frames with a crossing, the smallest closest distance over all frames.
# Exit code: 0 every frame free of crossings, 1 some frame has one, 2 bad input.
set -u
run=${1:?usage: scripts/check_frames.sh RUN_DIR [CHECK_INTERSECTIONS]}
tool=${2:-$(dirname "$0")/../build/release/tools/check_intersections}
[ -x "$tool" ] || { echo "check_frames: no check_intersections at $tool (build it first)" >&2; exit 2; }
shopt -s nullglob
frames=("$run"/frames/mesh_*.obj)
[ ${#frames[@]} -gt 0 ] || { echo "check_frames: $run/frames holds no mesh_NNNN.obj (run with \"output\": {\"obj\": true})" >&2; exit 2; }
bad=0
closest=""
for f in "${frames[@]}"; do
  n=${f##*mesh_}
  n=${n%.obj}
  obstacles=()
  [ -f "$run/frames/obstacles_$n.obj" ] && obstacles=("$run/frames/obstacles_$n.obj")
  out=$("$tool" "$f" "${obstacles[@]}")
  code=$?
  [ $code -eq 2 ] && exit 2
  [ $code -eq 1 ] && bad=$((bad + 1))
  self=$(sed -n 's/^self: \([0-9]*\) intersecting.*/\1/p' <<<"$out")
  obst=$(sed -n 's/^obstacle [^:]*: \([0-9]*\) intersecting.*/\1/p' <<<"$out")
  dist=$(sed -n 's/.*closest vertex \([^ ]*\) m.*/\1/p' <<<"$out")
  echo "frame $n: self $self, obstacle ${obst:--}, closest vertex ${dist:--} m"
  if [ -n "$dist" ]; then
    if [ -z "$closest" ] || awk -v a="$dist" -v b="$closest" 'BEGIN { exit !(a < b) }'; then closest=$dist; fi
  fi
done
echo "frames: ${#frames[@]}, with crossings: $bad, closest vertex over all frames: ${closest:--} m"
[ $bad -eq 0 ]
