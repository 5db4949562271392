#!/usr/bin/env bash
# Installs the Debian packages flexkin needs, if any is missing. Safe to run repeatedly.
set -euo pipefail
packages=(cmake make g++ pkg-config libeigen3-dev nlohmann-json3-dev libcli11-dev libgtest-dev
          libgmock-dev libbenchmark-dev libboost-dev libxsimd-dev liblapack-dev libnlopt-dev coinor-libipopt-dev)
packages+=(chromium)                     # the viewer's browser test (headless)
command -v node >/dev/null || packages+=(nodejs npm)  # Node only if there is none (e.g. NodeSource's)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The Node packages the tests use (tools/node/package-lock.json), after the Debian packages.
install_node_tools() {
  local dir tools
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  tools="$dir/tools/node"
  if [ ! -d "$tools/node_modules" ] || [ "$tools/package-lock.json" -nt "$tools/node_modules" ]; then
    echo "flexkin: installing the Node packages of tools/node (npm ci)"
    npm ci --prefix "$tools" --no-audit --no-fund
    touch "$tools/node_modules"
  fi
}
# On the way out, whichever exit is taken below, unless something failed.
trap 'status=$?; [ $status -ne 0 ] || install_node_tools' EXIT
[ ${#missing[@]} -eq 0 ] && exit 0
echo "flexkin: installing missing Debian packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "flexkin: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
