#!/usr/bin/env bash
# Blender imports the glTF of tree results (docs/gltf-export.md, "Trees"): runs the torso, the
# plant, the two-armed robot and the lift robot (prismatic joints) examples with the command
# line, writes their .glb with flexkin render, and checks each in headless Blender
# (tree_import_check.py). Run by ctest (tests/CMakeLists.txt):
#   tests/blender/tree_import.sh FLEXKIN_CLI SOURCE_DIR OUT_DIR
set -euo pipefail
cli=$1 source=$2 out=$3
source "$(dirname "$0")/require_blender.sh"
mkdir -p "$out"
for name in tree_torso tree_plant tree_robot_two_arms tree_robot_lift; do
  "$cli" run "$source/examples/$name.json" -o "$out/$name.npz" > /dev/null
  "$cli" render "$out/$name.npz" -o "$out" --formats glb --quiet
  log=$(blender -b --factory-startup --python "$source/tests/blender/tree_import_check.py" -- \
    "$out/$name.npz" "$out/$name.glb" 2>&1) || { echo "$log" >&2; echo "FAIL: $name" >&2; exit 1; }
  echo "$name: $(echo "$log" | grep '^blender ')"
  if ! echo "$log" | grep -q '^blender '; then
    echo "$log" >&2
    echo "FAIL: $name: no result line" >&2
    exit 1
  fi
done
