#!/usr/bin/env bash
# Installs the Debian packages flexkin needs, if any is missing. Safe to run repeatedly.
set -euo pipefail
packages=(cmake make g++ pkg-config libeigen3-dev nlohmann-json3-dev libcli11-dev libgtest-dev
          libgmock-dev libbenchmark-dev libboost-dev libxsimd-dev liblapack-dev libnlopt-dev coinor-libipopt-dev
          libcairo2-dev fonts-dejavu-core ffmpeg)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
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
