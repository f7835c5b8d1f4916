# ctest package_relocated: the installed programs run from a moved prefix. Run as
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DCONFIG=Release] [-DEXPECTED_VERSION=0.3.0]
#         [-DPYTHON=/usr/bin/python3 -DPYTHON_MODULE_DIR=lib/python3.11/dist-packages] -P run_relocated_test.cmake
# 1. cmake --install BUILD_DIR into WORK_DIR/stage, then moves it to WORK_DIR/moved/prefix (nothing of the stage
#    path is left); 2. runs the moved `tunnel --headless --frames 3` from an unrelated working directory (it must find
#    its assets beside itself) and checks its PNGs and that stats.json parses with 3 frames; `tunnel --assets` with a
#    wrong folder must fail naming it; 3. runs the moved `wiretool view` on a wire file and checks the PNG and the
#    stats; 4. with PYTHON: PYTHON_MODULE_DIR is a directory that interpreter searches under /usr/local or its own
#    prefix (so an install there needs no PYTHONPATH), and `import wires` from the moved prefix
#    (PYTHONPATH=prefix/PYTHON_MODULE_DIR) renders a wire and reports the project's version.
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_relocated_test.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT CONFIG)
  set(CONFIG Release)
endif()

function(run step)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK_DIR}/elsewhere" RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "relocated test, ${step} failed (${rc}):\n  ${ARGN}\n${out}")
  endif()
  message(STATUS "${step}: ok")
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

function(require_file path)
  if(NOT EXISTS "${path}")
    message(FATAL_ERROR "relocated test: ${path} was not written")
  endif()
  file(SIZE "${path}" size)
  if(size EQUAL 0)
    message(FATAL_ERROR "relocated test: ${path} is empty")
  endif()
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}/elsewhere" "${WORK_DIR}/moved")
set(stage "${WORK_DIR}/stage")
set(prefix "${WORK_DIR}/moved/prefix")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --config ${CONFIG} --prefix "${stage}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "relocated test: install failed (${rc}):\n${out}")
endif()
file(RENAME "${stage}" "${prefix}")

# The tunnel, headless, 3 frames, from a working directory that holds nothing of the level.
set(out_dir "${WORK_DIR}/tunnel_out")
run("moved tunnel --headless --frames 3" "${prefix}/bin/tunnel" --headless --frames 3 --width 320 --height 180
    --out "${out_dir}")
foreach(f frame_0000.png frame_0001.png frame_0002.png stats.json)
  require_file("${out_dir}/${f}")
endforeach()
file(READ "${out_dir}/stats.json" stats)
string(JSON frames LENGTH "${stats}" frames)
string(JSON non_finite GET "${stats}" summary non_finite)
if(NOT frames EQUAL 3 OR NOT non_finite EQUAL 0)
  message(FATAL_ERROR "relocated test: stats.json holds ${frames} frames, ${non_finite} non-finite (expected 3, 0)")
endif()
# --assets overrides the folder beside the executable; a wrong one is an error that names it.
execute_process(COMMAND "${prefix}/bin/tunnel" --headless --frames 1 --assets "${WORK_DIR}/no_such_assets"
                        --out "${WORK_DIR}/unused"
                WORKING_DIRECTORY "${WORK_DIR}/elsewhere" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(rc EQUAL 0 OR NOT out MATCHES "no_such_assets")
  message(FATAL_ERROR "relocated test: tunnel --assets with a missing folder: status ${rc}, output:\n${out}")
endif()
run("moved tunnel --assets share/wires/tunnel" "${prefix}/bin/tunnel" --headless --frames 1 --width 160 --height 90
    --assets "${prefix}/share/wires/tunnel" --out "${WORK_DIR}/tunnel_assets_out")
require_file("${WORK_DIR}/tunnel_assets_out/stats.json")
message(STATUS "moved tunnel: ok")

# wiretool view on a wire file outside the source tree.
file(WRITE "${WORK_DIR}/elsewhere/cable.json"
     [=[{"radius": 0.05, "nodes": [[-2, 1, 0], [-1, 0.2, 0], [0, 0, 0], [1, 0.2, 0], [2, 1, 0]]}]=])
run("moved wiretool view" "${prefix}/bin/wiretool" view cable.json --size 320x180 --png "${WORK_DIR}/view.png"
    --stats "${WORK_DIR}/view_stats.json")
require_file("${WORK_DIR}/view.png")
file(READ "${WORK_DIR}/view_stats.json" view_stats)
string(JSON visible GET "${view_stats}" frames 0 visible_wires)
if(NOT visible EQUAL 1)
  message(FATAL_ERROR "relocated test: wiretool view drew ${visible} wires, expected 1")
endif()
message(STATUS "moved wiretool: ok")

# The Python module from the moved prefix.
if(PYTHON AND PYTHON_MODULE_DIR)
  # Installed where a prefix's Python looks without PYTHONPATH: PYTHON_MODULE_DIR under /usr/local (Debian) or
  # under the interpreter's own prefix is on its sys.path as it starts.
  unset(ENV{PYTHONPATH})
  run("${PYTHON_MODULE_DIR} is on ${PYTHON}'s path" "${PYTHON}" -c
      "import os, sys\nd = '${PYTHON_MODULE_DIR}'\nhits = [p for p in ('/usr/local', sys.prefix) if os.path.join(p, d) in sys.path]\nassert hits, (d, sys.path)\nprint('on sys.path under', hits)")
  message(STATUS "${last_output}")
  set(ENV{PYTHONPATH} "${prefix}/${PYTHON_MODULE_DIR}")
  run("import wires from the moved prefix" "${PYTHON}" -c
      "import numpy as np, wires\nassert wires.__file__.startswith('${prefix}/'), wires.__file__\nrt = wires.Runtime(160, 90)\nw = rt.spawn(np.array([[-1.0, 0, 0], [0, -0.3, 0], [1, 0, 0]]), radius=0.05)\nrt.set_camera((0, 0, 4), (0, 0, 0))\nrt.update()\nimg = rt.render()\nassert img.shape == (90, 160, 4) and (img[..., :3].max(axis=2) > 60).any()\nprint('wires', wires.__version__, wires.__file__)")
  message(STATUS "${last_output}")
  if(EXPECTED_VERSION AND NOT last_output MATCHES "(^|\n)wires ${EXPECTED_VERSION} ")
    message(FATAL_ERROR "relocated test: wires.__version__ is not ${EXPECTED_VERSION}: ${last_output}")
  endif()
endif()
