# API reference with Doxygen (Debian's doxygen; tools/setup.sh --docs installs it):
#   cmake --build build --target docs   -> build/docs/html/index.html (every public header, README as main page)
# and, when Doxygen is found, the ctest checks below: Doxygen must report no undocumented public symbol
# (WARN_IF_UNDOCUMENTED, warnings to a file that must be empty).
find_package(Doxygen QUIET)

# Every installed target's include/ folder (cmake/Install.cmake's list).
set(wires_doc_dirs "")
foreach(target IN LISTS wires_targets)
  get_target_property(source_dir ${target} SOURCE_DIR)
  list(APPEND wires_doc_dirs "${source_dir}/include")
endforeach()

if(NOT DOXYGEN_FOUND)
  add_custom_target(docs
    COMMAND ${CMAKE_COMMAND} -E echo "docs: doxygen not found; install it with tools/setup.sh --docs"
    COMMAND ${CMAKE_COMMAND} -E false)
  return()
endif()

string(JOIN " " DOXY_INCLUDE_ROOTS ${wires_doc_dirs})
set(DOXY_INPUT "${DOXY_INCLUDE_ROOTS} ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/docs")
set(DOXY_MAINPAGE "${PROJECT_SOURCE_DIR}/README.md")
set(DOXY_OUTPUT "${CMAKE_BINARY_DIR}/docs")
set(DOXY_HTML YES)
set(DOXY_XML NO)
set(DOXY_WARN_LOG "${CMAKE_BINARY_DIR}/docs/warnings.txt")
configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${CMAKE_BINARY_DIR}/docs/Doxyfile @ONLY)
add_custom_target(docs
  COMMAND Doxygen::doxygen ${CMAKE_BINARY_DIR}/docs/Doxyfile
  COMMAND ${CMAKE_COMMAND} -E echo "docs: ${CMAKE_BINARY_DIR}/docs/html/index.html (warnings: ${DOXY_WARN_LOG})"
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "Doxygen: API reference"
  VERBATIM)

# ctest checks: Doxygen with WARN_IF_UNDOCUMENTED on a set of headers; any warning fails the test.
#   api_docs_wire_systems  the wire systems API (modules/wire/systems/include), every header
#   api_docs_game_api      the other headers a game calls in "Wires from game code" and examples/bullet_ropes:
#                          wire nodes, draw list and status, the wire renderer, ECS registry/entity/
#                          schedule/view, platform context/capture/expected/input, camera, frustum, lit renderer
#                          and meshes
function(wires_add_doc_check name)
  set(DOXY_INPUT "${ARGN}")
  string(REPLACE ";" " " DOXY_INPUT "${DOXY_INPUT}")
  set(DOXY_MAINPAGE "")
  set(DOXY_OUTPUT "${CMAKE_BINARY_DIR}/${name}")
  set(DOXY_HTML NO)
  set(DOXY_XML YES)  # some output must be generated for Doxygen to report undocumented members
  set(DOXY_WARN_LOG "${CMAKE_BINARY_DIR}/${name}/warnings.txt")
  configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${CMAKE_BINARY_DIR}/${name}/Doxyfile @ONLY)
  add_test(NAME ${name}
    COMMAND ${CMAKE_COMMAND} -DDOXYGEN=$<TARGET_FILE:Doxygen::doxygen> -DDOXYFILE=${CMAKE_BINARY_DIR}/${name}/Doxyfile
            -DLOG=${DOXY_WARN_LOG} -P ${PROJECT_SOURCE_DIR}/docs/check_doxygen.cmake)
  set_tests_properties(${name} PROPERTIES TIMEOUT 60 LABELS docs)
endfunction()

if(WIRE_BUILD_TESTS)
  wires_add_doc_check(api_docs_wire_systems ${PROJECT_SOURCE_DIR}/modules/wire/systems/include)
  set(src ${PROJECT_SOURCE_DIR})
  wires_add_doc_check(api_docs_game_api
    ${src}/modules/wire/include/wire/nodes.hpp ${src}/modules/wire/include/wire/draw.hpp
    ${src}/modules/wire/render/include/wire/render/wire_renderer.hpp
    ${src}/modules/wire/render/include/wire/render/install.hpp
    ${src}/engine/ecs/include/engine/ecs/registry.hpp ${src}/engine/ecs/include/engine/ecs/entity.hpp
    ${src}/engine/ecs/include/engine/ecs/schedule.hpp
    ${src}/engine/platform/include/engine/platform/context.hpp
    ${src}/engine/platform/include/engine/platform/capture.hpp
    ${src}/engine/platform/include/engine/platform/expected.hpp
    ${src}/engine/scene/include/engine/scene/camera.hpp
    ${src}/engine/ecs/include/engine/ecs/view.hpp ${src}/engine/platform/include/engine/platform/input.hpp
    ${src}/engine/gfx/include/engine/gfx/lit_renderer.hpp ${src}/engine/gfx/include/engine/gfx/mesh.hpp
    ${src}/engine/scene/include/engine/scene/frustum.hpp ${src}/modules/wire/include/wire/status.hpp)
endif()
