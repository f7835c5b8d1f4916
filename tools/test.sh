#!/usr/bin/env bash
# Builds and runs every test (README command (b); .ci/run runs exactly this).
# Installs missing packages first (fast when all are present), so it works on a fresh machine.
# Usage: tools/test.sh [--no-debug] [--no-asan] [--no-fuzz] [--help]
#   Stages: 1. Release build + ctest (build/), then pip install of the Python module into a fresh venv and its
#   pytest suite against that install (build/pip-venv/); 2. the wire module's numeric tests in a Debug build (build-debug/);
#   3. ASan+UBSan build + ctest (build-asan/); 4. every fuzz target for 5 seconds (tools/fuzz, build-fuzz/).
#   --no-debug / --no-asan / --no-fuzz skip 2 / 3 / 4.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
run_debug=1
run_asan=1
run_fuzz=1
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --no-debug) run_debug=0 ;;
    --no-asan) run_asan=0 ;;
    --no-fuzz) run_fuzz=0 ;;
    *) echo "test.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
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

# 1b. The Python module as a user installs it: `pip install ./python` into a fresh virtual environment (reusing
# build/, so only the module is relinked and installed), then the pytest suite against that install, from outside
# the source tree with no PYTHONPATH (tools/pip_install_test.sh).
if compgen -G "build/python/wires*.so" >/dev/null; then
  echo "test.sh: pip stage (build/pip-venv/)"
  bash tools/pip_install_test.sh --build-dir build --venv build/pip-venv
fi

# 2. The wire module's numeric tests without optimization: its wide-lane kernels are compiled under
# `#pragma GCC target` and rely on inlining across that boundary, which -O0 does not do (a Debug build once
# computed garbage LOD ranges that every optimized build got right). Only these tests: a Debug build of all of
# them would double the stage-1 time.
if [ "$run_debug" -eq 1 ]; then
  echo "test.sh: Debug stage (build-debug/)"
  generator=()
  if [ ! -f build-debug/CMakeCache.txt ]; then generator=(-G Ninja); fi
  cmake -S . -B build-debug "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug -DWIRE_BUILD_BENCHMARKS=OFF \
    -DWIRE_WERROR="$werror"
  # wire_curve_test is left out: 150 s at -O0, and the kernels it covers are also in wire_curve_family_test.
  debug_tests=(wire_curve_family_test wire_ring_test wire_lod_test wire_systems_test wire_systems_alloc_test)
  cmake --build build-debug --parallel "$jobs" --target "${debug_tests[@]}"
  for t in "${debug_tests[@]}"; do build-debug/bin/"$t" --gtest_brief=1; done
  # The LOD's lane kernels at the narrower widths too (wire_lod_test: the LOD proof; the systems drive them too).
  for lanes in 2 4; do
    for t in wire_lod_test wire_systems_test; do WIRE_LOD_LANES="$lanes" build-debug/bin/"$t" --gtest_brief=1; done
  done
fi

# 3. The same tests under AddressSanitizer + UndefinedBehaviorSanitizer (any report fails the test).
# Leak suppressions cover the Mesa/LLVM/EGL driver libraries only (tools/sanitizers/lsan.supp), never our code.
if [ "$run_asan" -eq 1 ]; then
  echo "test.sh: ASan+UBSan stage (build-asan/)"
  generator=()
  if [ ! -f build-asan/CMakeCache.txt ]; then generator=(-G Ninja); fi
  # Warnings are enforced by stage 1; GCC's sanitizer instrumentation adds false -Wmaybe-uninitialized and
  # -Wstringop-* reports, so this stage does not use -Werror.
  # -O1 -g1 (line tables: stack traces keep file and line): this stage's build was 16 of CI's 32 minutes at -O2 -g
  # on 2 cores; -O1 -g1 compiles the heaviest file in 46% of the time (gltf.cpp: 73 s -> 34 s), and -O1 is
  # what ASan's authors recommend.
  cmake -S . -B build-asan "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DWIRE_SANITIZE=ON \
    -DWIRE_BUILD_BENCHMARKS=OFF -DWIRE_WERROR=OFF \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
  cmake --build build-asan --parallel "$jobs"
  export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:print_stacktrace=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=0"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
  export LSAN_OPTIONS="suppressions=$here/tools/sanitizers/lsan.supp:print_suppressions=0"
  # libEGL_mesa dlclose()s the llvmpipe driver at exit, before LeakSanitizer runs: blocks held only by the
  # driver's globals then show as leaks in "<unknown module>", which no suppression can name. Preloading the
  # driver keeps it mapped (those blocks stay reachable); ASan then cannot be first in the library list.
  dri="$(ls /usr/lib/*/dri/swrast_dri.so 2>/dev/null | head -n 1 || true)"
  if [ -n "$dri" ]; then
    export ASAN_OPTIONS="$ASAN_OPTIONS:verify_asan_link_order=0"
    LD_PRELOAD="$dri${LD_PRELOAD:+:$LD_PRELOAD}" ctest --test-dir build-asan --output-on-failure --parallel "$jobs"
  else
    ctest --test-dir build-asan --output-on-failure --parallel "$jobs"
  fi
fi

# 4. Each fuzz target briefly on a copy of its seed corpus (tools/fuzz; long runs are manual).
if [ "$run_fuzz" -eq 1 ]; then
  echo "test.sh: fuzz stage (build-fuzz/)"
  for target in $(tools/fuzz list); do
    tools/fuzz run "$target" 5
  done
fi
