#!/usr/bin/env bash
# The flexkin add-on for Blender (blender/flexkin_blender, docs/blender.md) in headless Blender:
# zips the add-on as users install it, and runs bake_chain_check.py, which installs and enables
# it, bakes bone chains and checks them against flexkin's own results. Run by ctest
# (tests/CMakeLists.txt):
#   tests/blender/addon.sh SOURCE_DIR PYTHON_MODULE_DIR OUT_DIR
set -euo pipefail
source=$1 module=$2 out=$3
if ! command -v blender > /dev/null; then
  echo "FAIL: blender is not installed; run scripts/install-deps.sh" >&2
  exit 1
fi
mkdir -p "$out"
rm -f "$out/flexkin_blender.zip"
(cd "$source/blender" && /usr/bin/python3 -m zipfile -c "$out/flexkin_blender.zip" flexkin_blender)
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
