# ctest package_install: the installed CMake package end to end. Run as
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX_COMPILER=... [-DLAUNCHER=...]
#         -DEXPECTED_VERSION=0.3.0 [-DCONFIG=Release] [-DPYTHON_MODULE_DIR=lib/python3.11/dist-packages]
#         -P run_package_test.cmake
# 1. cmake --install BUILD_DIR into WORK_DIR/stage, then moves it to WORK_DIR/prefix (the package must be
#    relocatable); 2. checks the layout (config + version files, bin/ holding wiretool and tunnel only, the tunnel's
#    assets, the Python module when built, no tests installed, no installed file naming the source or build tree)
#    and the version rule; a configure of tests/package asking for find_package(wires 0.2) must fail with CMake's
#    version message; 3. configures, builds and runs tests/package against
#    it with nothing but CMAKE_PREFIX_PATH pointing at the prefix: the README example (wires_consumer) and the
#    repository's modules/wire/systems/examples/spawn_wires.cpp linking only wires::wire_systems.
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER EXPECTED_VERSION)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_package_test.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT CONFIG)
  set(CONFIG Release)
endif()

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "package test, ${step} failed (${rc}):\n  ${ARGN}\n${out}")
  endif()
  message(STATUS "${step}: ok")
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(stage "${WORK_DIR}/stage")
set(prefix "${WORK_DIR}/prefix")
run("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --config ${CONFIG} --prefix "${stage}")
file(RENAME "${stage}" "${prefix}")

# Layout.
set(pkg "${prefix}/lib/cmake/wires")
foreach(f wiresConfig.cmake wiresConfigVersion.cmake wiresTargets.cmake wiresDependencies.cmake)
  if(NOT EXISTS "${pkg}/${f}")
    message(FATAL_ERROR "package test: ${pkg}/${f} was not installed")
  endif()
endforeach()
foreach(h wire/systems/api.hpp wire/render/wire_renderer.hpp engine/ecs/registry.hpp engine/platform/context.hpp)
  if(NOT EXISTS "${prefix}/include/${h}")
    message(FATAL_ERROR "package test: header include/${h} was not installed")
  endif()
endforeach()
# Programs and the tunnel's assets (docs/install.md); no tests, benchmarks or examples.
file(GLOB top RELATIVE "${prefix}" "${prefix}/*")
if(NOT top STREQUAL "bin;include;lib;share")
  message(FATAL_ERROR "package test: the prefix holds '${top}', expected bin, include, lib and share")
endif()
file(GLOB programs RELATIVE "${prefix}/bin" "${prefix}/bin/*")
if(NOT programs STREQUAL "tunnel;wiretool")
  message(FATAL_ERROR "package test: bin holds '${programs}', expected tunnel and wiretool only (no tests, benchmarks)")
endif()
foreach(f straight_section.glb wall_details.glb cable_hooks.glb anchors.json)
  if(NOT EXISTS "${prefix}/share/wires/tunnel/${f}")
    message(FATAL_ERROR "package test: the tunnel's asset share/wires/tunnel/${f} was not installed")
  endif()
endforeach()
if(PYTHON_MODULE_DIR)
  file(GLOB module "${prefix}/${PYTHON_MODULE_DIR}/wires*.so")
  if(NOT module)
    message(FATAL_ERROR "package test: the Python module was not installed into ${PYTHON_MODULE_DIR}")
  endif()
endif()
file(GLOB_RECURSE installed "${prefix}/*")
# Test support (modules/wire/testing: random families, exact references; modules/wire/render/testing: the compute
# programs driven alone) is never installed: no header, and no symbol of it in any installed library
# (wire::families, wire::testing, the Catenary reference, the pop-free family, the curve stage's test hooks
# wire::detail::spread_test and node_segment_records, GpuCurvePass, GpuRingPass).
foreach(f IN LISTS installed)
  if(f MATCHES "/include/wire/testing/|/include/wire/render/testing/")
    message(FATAL_ERROR "package test: test-support header installed: ${f}")
  endif()
  if(f MATCHES "\\.(a|so)$")
    file(STRINGS "${f}" support REGEX "wire8families|wire7testing|8Catenary|PopFreeFamily|13PopFreeEvent|11spread_test|20node_segment_records|12GpuCurvePass|11GpuRingPass")
    if(support)
      list(GET support 0 first)
      message(FATAL_ERROR "package test: ${f} holds test-support code: ${first}")
    endif()
  endif()
endforeach()
string(REGEX REPLACE "([][+.*()^$?|\\])" "\\\\\\1" source_re "${SOURCE_DIR}")
string(REGEX REPLACE "([][+.*()^$?|\\])" "\\\\\\1" build_re "${BUILD_DIR}")
foreach(f IN LISTS installed)
  file(STRINGS "${f}" refs REGEX "${source_re}|${build_re}")
  if(refs)
    list(GET refs 0 first)
    message(FATAL_ERROR "package test: ${f} names the source or build tree (not relocatable): ${first}")
  endif()
endforeach()

# Version rule (semantic versioning, 0.x: a minor version may break the API): 0.3 accepts 0.3 and 0.3.x, not
# 0.2, 0.1, 0.4 or 1.0.
foreach(want 0.3:TRUE 0.3.0:TRUE 0.2:FALSE 0.1:FALSE 0.4:FALSE 1.0:FALSE)
  string(REPLACE ":" ";" want "${want}")
  list(GET want 0 PACKAGE_FIND_VERSION)
  list(GET want 1 expected)
  string(REPLACE "." ";" parts "${PACKAGE_FIND_VERSION}")
  list(GET parts 0 PACKAGE_FIND_VERSION_MAJOR)
  list(GET parts 1 PACKAGE_FIND_VERSION_MINOR)
  set(PACKAGE_FIND_VERSION_RANGE FALSE)
  unset(PACKAGE_VERSION_COMPATIBLE)
  set(CMAKE_SIZEOF_VOID_P 8)
  include("${pkg}/wiresConfigVersion.cmake")
  if(NOT PACKAGE_VERSION_COMPATIBLE STREQUAL expected AND NOT (expected AND PACKAGE_VERSION_COMPATIBLE))
    message(FATAL_ERROR "package test: find_package(wires ${PACKAGE_FIND_VERSION}) compatible = "
                        "'${PACKAGE_VERSION_COMPATIBLE}', expected ${expected} (package ${PACKAGE_VERSION})")
  endif()
endforeach()
if(NOT PACKAGE_VERSION VERSION_EQUAL "${EXPECTED_VERSION}")
  message(FATAL_ERROR "package test: the package says version ${PACKAGE_VERSION}, the project ${EXPECTED_VERSION}")
endif()
message(STATUS "layout and version ${PACKAGE_VERSION}: ok")

# The consumer project, built against the prefix only.
set(launcher_args "")
if(LAUNCHER)
  set(launcher_args "-DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}")
endif()
# A project pinned to 0.2 (the API before Camera went double) is refused, with CMake's own version message.
execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package" -B "${WORK_DIR}/consumer_0_2"
                -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=${CONFIG} "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
                "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DWIRES_FIND_VERSION=0.2
                "-DWIRES_README=${SOURCE_DIR}/README.md"
                "-DWIRES_SPAWN_EXAMPLE=${SOURCE_DIR}/modules/wire/systems/examples/spawn_wires.cpp"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
string(REGEX REPLACE "[ \n]+" " " flat "${out}")
if(rc EQUAL 0 OR NOT flat MATCHES "compatible with requested version \"0\\.2\"" OR
   NOT flat MATCHES "wiresConfig\\.cmake, version: ${EXPECTED_VERSION}")
  message(FATAL_ERROR "package test: find_package(wires 0.2) against ${EXPECTED_VERSION} was not refused with "
                      "CMake's version message (status ${rc}):\n${out}")
endif()
message(STATUS "find_package(wires 0.2) refused: ok")

run("configure tests/package" ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package" -B "${WORK_DIR}/consumer"
    -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=${CONFIG} "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" ${launcher_args}
    "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
    "-DWIRES_README=${SOURCE_DIR}/README.md"
    "-DWIRES_SPAWN_EXAMPLE=${SOURCE_DIR}/modules/wire/systems/examples/spawn_wires.cpp")
run("build tests/package" ${CMAKE_COMMAND} --build "${WORK_DIR}/consumer" --config ${CONFIG})
find_program(consumer wires_consumer PATHS "${WORK_DIR}/consumer" "${WORK_DIR}/consumer/${CONFIG}" NO_DEFAULT_PATH
             REQUIRED)
set(ENV{WIRES_CONSUMER_PNG} "${WORK_DIR}/consumer.png")
run("run wires_consumer" "${consumer}")
message(STATUS "${last_output}")
find_program(spawn spawn_wires_example PATHS "${WORK_DIR}/consumer" "${WORK_DIR}/consumer/${CONFIG}"
             NO_DEFAULT_PATH REQUIRED)
run("run spawn_wires_example (wires::wire_systems only)" "${spawn}")
if(NOT last_output MATCHES "frame 5: 2 wires, 1 visible")
  message(FATAL_ERROR "spawn_wires_example: unexpected output:\n${last_output}")
endif()
