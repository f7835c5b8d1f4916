#!/usr/bin/env bash
# The Python module as a user installs it: `pip install ./python` into a fresh virtual environment, then the pytest
# suite (tests/python) against that installed package, not the build tree (tools/test.sh stage 1b).
# Usage: tools/pip_install_test.sh [--build-dir DIR] [--venv DIR]
#   --build-dir DIR  reuse this configured CMake tree (WIRES_CMAKE_BUILD_DIR: only the module is relinked and
#                    installed); without it pip builds the module in a fresh temporary tree (minutes).
#   --venv DIR       where the environment is made (default: build/pip-venv; removed first).
# Debian's pip, venv, numpy and pytest (tools/setup.sh): the venv sees them (--system-site-packages) and pip builds
# without isolation, since these machines reach no package index.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir=""
venv="$here/build/pip-venv"
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --build-dir) build_dir="$(cd "$2" && pwd)"; shift ;;
    --venv) venv="$2"; shift ;;
    *) echo "pip_install_test.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
mkdir -p "$(dirname "$venv")"
venv="$(cd "$(dirname "$venv")" && pwd)/$(basename "$venv")"

rm -rf "$venv"
/usr/bin/python3 -m venv --system-site-packages "$venv"
if [ -n "$build_dir" ]; then export WIRES_CMAKE_BUILD_DIR="$build_dir"; fi
"$venv/bin/pip" install --no-build-isolation --no-index --disable-pip-version-check -q "$here/python"

# From a folder outside the source tree, with no PYTHONPATH: only the installed package can be imported.
unset PYTHONPATH
outside="$(mktemp -d)"
trap 'rm -rf "$outside"' EXIT
cd "$outside"
"$venv/bin/python" -c "import wires, sys; assert wires.__file__.startswith(sys.argv[1] + '/'), wires.__file__; print('pip_install_test: wires', wires.__version__, 'from', wires.__file__)" "$venv"
# The README's own check of the install (its `v/bin/python -c "import wires; ..."` line, v/ being this venv):
# renders a wire headless (some pixels drawn).
readme_check="$(grep -m 1 '^v/bin/python -c ' "$here/README.md" || true)"
if [ -z "$readme_check" ]; then echo "pip_install_test: README.md has no 'v/bin/python -c' line" >&2; exit 1; fi
readme_out="$(eval "\"$venv/bin/python\"${readme_check#v/bin/python}")"
echo "pip_install_test: README check: $readme_out"
if ! [[ "$readme_out" =~ [1-9][0-9]*\ wire\ pixels ]]; then
  echo "pip_install_test: the README's check drew no wire" >&2; exit 1
fi
# WIRES_EXPECTED_PREFIX: test_wires.py asserts the module it tests lives there.
# WIRETOOL: the tests that compare with wiretool run where it was built (skipped, saying so, where it was not).
wiretool="${build_dir:-$here/build}/bin/wiretool"
if [ -x "$wiretool" ]; then export WIRETOOL="$wiretool"; fi
WIRES_EXPECTED_PREFIX="$venv" "$venv/bin/python" -m pytest -q -p no:cacheprovider "$here/tests/python"
