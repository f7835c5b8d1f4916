#!/usr/bin/env bash
# Builds and runs every test (README command (b); .ci/run runs exactly this).
# Installs missing packages first (fast when all are present), so it works on a fresh machine.
# Usage: tools/test.sh [--help]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
case "${1:-}" in
  -h|--help) sed -n '2,4p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
  "") ;;
  *) echo "test.sh: unknown option '$1'" >&2; exit 2 ;;
esac
cd "$here"
bash tools/setup.sh --no-build

jobs="$(nproc)"
werror=OFF
if [ -n "${CI:-}" ]; then werror=ON; fi

# 1. The Release build with every test.
generator=()
if [ ! -f build/CMakeCache.txt ]; then generator=(-G Ninja); fi
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DWIRE_WERROR="$werror"
cmake --build build --parallel "$jobs"
ctest --test-dir build --output-on-failure --parallel "$jobs"
