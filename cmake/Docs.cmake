# API reference with Doxygen (Debian's doxygen; tools/setup.sh --docs installs it):
#   cmake --build build --target docs   -> build/docs/html/index.html (every public header, README as main page)
# and, when Doxygen is found, ctest api_docs_wire_systems: Doxygen must report no undocumented public symbol of
# the wire systems API (modules/wire/systems/include; WARN_IF_UNDOCUMENTED, warnings to a file that must be empty).
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
set(DOXY_INPUT "${DOXY_INCLUDE_ROOTS} ${PROJECT_SOURCE_DIR}/README.md")
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

if(WIRE_BUILD_TESTS)
  set(DOXY_INPUT "${PROJECT_SOURCE_DIR}/modules/wire/systems/include")
  set(DOXY_MAINPAGE "")
  set(DOXY_OUTPUT "${CMAKE_BINARY_DIR}/docs_check")
  set(DOXY_HTML NO)
  set(DOXY_XML YES)  # some output must be generated for Doxygen to report undocumented members
  set(DOXY_WARN_LOG "${CMAKE_BINARY_DIR}/docs_check/warnings.txt")
  configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${CMAKE_BINARY_DIR}/docs_check/Doxyfile @ONLY)
  add_test(NAME api_docs_wire_systems
    COMMAND ${CMAKE_COMMAND} -DDOXYGEN=$<TARGET_FILE:Doxygen::doxygen> -DDOXYFILE=${CMAKE_BINARY_DIR}/docs_check/Doxyfile
            -DLOG=${DOXY_WARN_LOG} -P ${PROJECT_SOURCE_DIR}/docs/check_doxygen.cmake)
  set_tests_properties(api_docs_wire_systems PROPERTIES TIMEOUT 60 LABELS docs)
endif()
