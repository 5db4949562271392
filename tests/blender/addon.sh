#!/usr/bin/env bash
# The flexkin add-on for Blender (blender/addons/flexkin_blender, docs/blender.md) in headless
# Blender: zips the add-on as users install it, and runs bake_chain_check.py, which installs and
# enables it, bakes chains, trees, ropes and hair and checks them against flexkin's own results;
# then enables it by path (the repository's blender/ folder as the scripts folder). Run by ctest
# (tests/CMakeLists.txt):
#   tests/blender/addon.sh SOURCE_DIR PYTHON_MODULE_DIR OUT_DIR
set -euo pipefail
source=$1 module=$2 out=$3
source "$(dirname "$0")/require_blender.sh"
mkdir -p "$out"
rm -f "$out/flexkin_blender.zip"
(cd "$source/blender/addons" && /usr/bin/python3 -m zipfile -c "$out/flexkin_blender.zip" flexkin_blender)
# The add-on is installed into a user folder of the test's own, not the machine's.
export BLENDER_USER_SCRIPTS="$out/scripts" BLENDER_USER_CONFIG="$out/config"
log=$(blender -b --factory-startup --python "$source/tests/blender/bake_chain_check.py" -- \
  "$out/flexkin_blender.zip" "$module" "$source" "$out" 2>&1) || { echo "$log" >&2; echo "FAIL: bake_chain_check" >&2; exit 1; }
echo "$log" | grep -E '^(blender |report: |timing: |operators: )'
if ! echo "$log" | grep -q '^ok$'; then
  echo "$log" >&2
  echo "FAIL: bake_chain_check did not finish" >&2
  exit 1
fi
# Installed by path: the repository's blender/ folder as Blender's scripts folder (it holds
# addons/flexkin_blender), the add-on enabled from there.
log=$(BLENDER_USER_SCRIPTS="$source/blender" BLENDER_USER_CONFIG="$out/config_by_path" blender -b --factory-startup --python-expr '
import bpy, os, sys
sys.dont_write_bytecode = True
bpy.ops.preferences.addon_enable(module="flexkin_blender")
module = sys.modules.get("flexkin_blender")
ok = hasattr(bpy.ops.flexkin, "bake_chain") and module is not None
print("by path: " + (os.path.relpath(module.__file__, sys.argv[-1]) if ok else "not enabled"))
os._exit(0 if ok else 1)' -- "$source" 2>&1) || { echo "$log" >&2; echo "FAIL: by path" >&2; exit 1; }
echo "$log" | grep '^by path: ' || { echo "$log" >&2; echo "FAIL: by path" >&2; exit 1; }
