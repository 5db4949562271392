# Sourced by the Blender checks (tests/blender/*.sh): fails with exit status 1, saying how to
# install it, where Debian's Blender is not on the PATH.
if ! command -v blender > /dev/null; then
  echo "FAIL: blender is not installed; run scripts/install-deps.sh" >&2
  exit 1
fi
