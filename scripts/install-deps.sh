#!/usr/bin/env bash
# Installs what flexkin needs, if anything is missing: Debian packages (apt-get), then the npm
# packages of tools/node that the tests use (npm ci, exact versions from its package-lock.json).
# Safe to run repeatedly.
set -euo pipefail
packages=(cmake make g++ ccache pkg-config clang-format git libeigen3-dev nlohmann-json3-dev libcli11-dev libgtest-dev
          libgmock-dev libbenchmark-dev libboost-dev libxsimd-dev liblapack-dev libnlopt-dev coinor-libipopt-dev)
packages+=(libcairo2-dev fonts-dejavu-core ffmpeg)  # flexkin render (src/render)
packages+=(libtinygltf-dev)  # glTF export (src/gltf)
packages+=(clang-14 libclang-rt-14-dev)  # libFuzzer targets, ASan + UBSan (fuzz/, make fuzz, docs/fuzzing.md)
packages+=(liborocos-kdl-dev)  # the pseudo-inverse peer of the arm comparison (testing/kdl_peer.h)
packages+=(libkdl-parser-dev)  # KDL chains from URDF text, the URDF snakes' peer (testing/kdl_urdf_peer.h)
packages+=(chromium)         # the viewer's browser test (headless)
packages+=(blender)          # glTF of trees imported by Blender, headless (tests/blender)
packages+=(liburdfdom-dev libtinyxml-dev)  # URDF arms (src/urdf); TinyXML, the parser urdfdom uses
packages+=(libfcl-dev)        # mesh colliders' hierarchy; the colliders' reference distances (tests/colliders_test.cc)
packages+=(libassimp-dev)     # mesh colliders' STL and OBJ files (src/io/mesh_file.cc)
packages+=(zlib1g-dev)       # CRC-32 of the .npz result files (src/io/npz.cc)
packages+=(python3-numpy)    # the tests read .npz results with numpy.load (tests/result_npz_test)
packages+=(python3-dev pybind11-dev python3-pytest)  # the Python module (python/, docs/python.md)
packages+=(python3-venv python3-pip python3-setuptools)  # its pip install, tested (python/tests/test_pip.py)
packages+=(python3-matplotlib python3-distributed python3-tqdm)  # its examples (examples/python)
# Node.js runs the glTF validator and the browser test. Debian's nodejs and npm only if there is
# no node or npm on the PATH: one from another source (e.g. NodeSource) is used as it is.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then packages+=(nodejs npm); fi

# The npm packages of tools/node, when tools/node/node_modules is missing or older than the lock.
install_node_tools() {
  local dir
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tools/node"
  if [ ! -d "$dir/node_modules" ] || [ "$dir/package-lock.json" -nt "$dir/node_modules" ]; then
    echo "flexkin: installing the npm packages of tools/node (npm ci)"
    npm ci --prefix "$dir" --no-audit --no-fund
    touch "$dir/node_modules"
  fi
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "flexkin: installing missing Debian packages: ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "flexkin: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo=sudo
  fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
install_node_tools
