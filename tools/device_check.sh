#!/usr/bin/env bash
# The GPU checks for a machine with a hardware EGL device (an NVIDIA, AMD or Intel GPU): the GL tests on it, then
# `wiretool bench --gl` with 1,000, 10,000 and 100,000 moving cables, figures written to OUT.
# Usage:
#   tools/device_check.sh [--bin DIR] [--out DIR] [--wires LIST] [--tests-only | --bench-only]
#     runs on the machine with the GPU (WIRE_EGL_PLATFORM=device: fails at once, saying so, without a hardware
#     device); --bin: the binaries (default build/bin; a packed folder's bin/, whose lib/ is put on
#     LD_LIBRARY_PATH); --out: default out/device_check; --wires: default 1000,10000,100000
#   tools/device_check.sh --pack DIR
#     on this machine: copies the Release binaries it runs, their non-system shared libraries (ldd) and this
#     script into DIR (bin/, lib/), for a machine that has none of the project's packages; run DIR/device_check.sh
#     there.
#   WIRE_EGL_PLATFORM=surfaceless tools/device_check.sh --wires 1000 makes a dry run on llvmpipe.
# Writes OUT/tests/*.log, OUT/bench_<N>/ (bench_gl.csv, bench_gl.md) and OUT/summary.md (also printed). Exit status:
# 0 when every test passed and every bench ran, 1 otherwise, 2 on bad usage or no hardware device.
set -uo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
bin="" out="out/device_check" wires="1000,10000,100000" pack="" tests=1 bench=1
usage() { sed -n '2,15p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --bin) bin="${2:?--bin needs a folder}"; shift ;;
    --out) out="${2:?--out needs a folder}"; shift ;;
    --wires) wires="${2:?--wires needs a list}"; shift ;;
    --pack) pack="${2:?--pack needs a folder}"; shift ;;
    --tests-only) bench=0 ;;
    --bench-only) tests=0 ;;
    *) echo "device_check.sh: unknown option '$1' (--help lists them)" >&2; exit 2 ;;
  esac
  shift
done
programs=(wiretool wire_render_test wire_shader_resources_test gfx_test system_render_test curved_space_gpu_test)

if [ -n "$pack" ]; then
  src="${bin:-$root/build/bin}"
  mkdir -p "$pack/bin" "$pack/lib" || exit 1
  for p in "${programs[@]}"; do
    [ -x "$src/$p" ] || { echo "device_check.sh: $src/$p is missing: build Release first (tools/setup.sh)" >&2; exit 1; }
    cp "$src/$p" "$pack/bin/"
    # Every shared library but the C runtime's own (the loader, libc, libm, libpthread, libdl, librt) and the
    # vendor GL drivers, which the GPU machine has: glvnd's libEGL/libOpenGL dispatch to its driver.
    ldd "$src/$p" | awk '/=> \// {print $3}' | while read -r lib; do
      case "$(basename "$lib")" in
        ld-linux*|libc.so*|libm.so*|libpthread.so*|libdl.so*|librt.so*|libEGL_mesa*|libGLX_mesa*|libgallium*) ;;
        *) cp -L "$lib" "$pack/lib/" ;;
      esac
    done
  done
  # epoxy loads the glvnd dispatch libraries at run time (dlopen): carried too.
  for lib in libEGL.so.1 libOpenGL.so.0 libGLdispatch.so.0; do
    found="$(ldconfig -p | awk -v l="$lib" '$1 == l && /x86-64/ {print $NF; exit}')"
    [ -n "$found" ] && cp -L "$found" "$pack/lib/"
  done
  cp "${BASH_SOURCE[0]}" "$pack/device_check.sh"
  echo "device_check.sh: packed $(ls "$pack/bin" | wc -l) programs and $(ls "$pack/lib" | wc -l) libraries into $pack"
  echo "  there: $pack/device_check.sh --bin $pack/bin"
  exit 0
fi

if [ -z "$bin" ]; then
  if [ -x "$here/bin/wiretool" ]; then bin="$here/bin"; else bin="$root/build/bin"; fi
fi
[ -x "$bin/wiretool" ] || { echo "device_check.sh: no wiretool in $bin (--bin DIR)" >&2; exit 2; }
if [ -d "$bin/../lib" ]; then export LD_LIBRARY_PATH="$(cd "$bin/../lib" && pwd)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"; fi
# A hardware device or nothing: llvmpipe figures are not what this measures (WIRE_EGL_PLATFORM=surfaceless set by
# the caller makes a dry run of the script on llvmpipe).
export WIRE_EGL_PLATFORM="${WIRE_EGL_PLATFORM:-device}"
mkdir -p "$out/tests" || exit 1
status=0

# The device and its GL: one small view, whose log names the EGL device and the renderer.
probe="$out/probe"
mkdir -p "$probe"
printf '{"wires":[{"radius":0.02,"nodes":[[-1,0,0],[0,-0.3,0],[1,0,0]]}]}' > "$probe/wire.json"
if ! "$bin/wiretool" view "$probe/wire.json" --path nodes --size 320x180 --png "$probe/wire.png" \
    --csv "$probe/rings.csv" > "$probe/log.txt" 2>&1; then
  cat "$probe/log.txt" >&2
  echo "device_check.sh: no usable EGL device here (WIRE_EGL_PLATFORM=$WIRE_EGL_PLATFORM); run tools/test.sh on llvmpipe" >&2
  exit 2
fi
device_line="$(grep -m1 'headless EGL' "$probe/log.txt" || echo 'headless EGL: (not printed)')"

summary="$out/summary.md"
{
  echo "# Device check $(date -u +%Y-%m-%dT%H:%MZ)"
  echo
  echo "- $device_line"
  command -v nvidia-smi > /dev/null && echo "- $(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null)"
  echo
} > "$summary"

if [ "$tests" -eq 1 ]; then
  echo "| GL test program | result | seconds |" >> "$summary"
  echo "| --- | --- | --- |" >> "$summary"
  for t in wire_shader_resources_test gfx_test wire_render_test system_render_test curved_space_gpu_test; do
    [ -x "$bin/$t" ] || { echo "| $t | missing | |" >> "$summary"; status=1; continue; }
    start=$(date +%s)
    if (cd "$out/tests" && "$bin/$t" --gtest_brief=1 > "$t.log" 2>&1); then r=passed; else r="**failed**"; status=1; fi
    echo "| $t | $r ($(grep -m1 -oE '[0-9]+ tests? from [0-9]+ test suites? ran' "$out/tests/$t.log")) | $(( $(date +%s) - start )) |" >> "$summary"
    # The printed figures (GPU vs CPU references): kept in the summary for comparison with llvmpipe's.
    grep -hE '^(drawn rings|gpu-nodes|GpuRings|curves|frames|lod)' "$out/tests/$t.log" | head -20 | sed 's/^/    /' >> "$summary"
  done
  echo >> "$summary"
fi

if [ "$bench" -eq 1 ]; then
  IFS=',' read -r -a counts <<< "$wires"
  for n in "${counts[@]}"; do
    dir="$out/bench_$n"
    if "$bin/wiretool" bench --gl --no-systems --no-accuracy --scenes swaying --wires "$n" --size 1920x1080 \
        --out "$dir" > "$dir.log" 2>&1; then
      { echo "## swaying, $n moving cables, 1920x1080"; echo; tail -n +1 "$dir/bench_gl.md" | grep -E '^\|' ; echo; } >> "$summary"
    else
      echo "## swaying, $n cables: **failed** (see $dir.log)" >> "$summary"
      status=1
    fi
  done
fi
cat "$summary"
exit "$status"
