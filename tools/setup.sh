#!/usr/bin/env bash
# Installs every system package the project needs (Debian), then configures and builds.
# Idempotent: when every package is present it skips apt-get entirely and only builds.
# The Python module is built for and tested with Debian's /usr/bin/python3 (its numpy, pybind11 and pytest); pip and
# venv for `pip install ./python` into a virtual environment (docs/python.md).
# Usage: tools/setup.sh [--no-build] [--build-dir DIR] [--type Release|Debug|RelWithDebInfo] [--docs]
#   --docs also installs Doxygen (for `cmake --build build --target docs`, the API reference).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$here/build"
build_type="Release"
do_build=1
do_docs=0

usage() {
  sed -n '2,7p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) do_build=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    --type) build_type="$2"; shift ;;
    --docs) do_docs=1 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "setup.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done

# One list, used by set-up and CI alike. Keep it sorted.
packages=(
  build-essential
  clang
  cmake
  gnuplot-nox
  libbenchmark-dev
  libbullet-dev
  libclang-rt-14-dev
  libcli11-dev
  libegl-dev
  libegl-mesa0
  libepoxy-dev
  libgl1-mesa-dri
  libglfw3-dev
  libglm-dev
  libgmock-dev
  libgtest-dev
  libimgui-dev
  libosd-dev
  libstb-dev
  libtbb-dev
  libtinygltf-dev
  ninja-build
  nlohmann-json3-dev
  pkg-config
  pybind11-dev
  python3-dev
  python3-numpy
  python3-pip
  python3-pytest
  python3-venv
)
# Only when asked (--docs): the API reference generator.
if [ "$do_docs" -eq 1 ]; then packages+=(doxygen); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} packages present"
fi

if [ "$do_build" -eq 1 ]; then
  generator=()
  if command -v ninja >/dev/null 2>&1 && [ ! -f "$build_dir/Makefile" ]; then generator=(-G Ninja); fi
  cmake -S "$here" -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE="$build_type"
  cmake --build "$build_dir" --parallel "$(nproc)"
fi
