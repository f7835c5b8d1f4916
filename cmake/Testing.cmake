# wire_add_test(NAME name SOURCES a.cpp ... LIBS lib ... [TIMEOUT seconds] [LABELS l ...])
# One GoogleTest executable per module; each test case shows in ctest with a time limit.
include(GoogleTest)
function(wire_add_test)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 120)
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main)
  wire_set_warnings(${T_NAME})
  target_compile_definitions(${T_NAME} PRIVATE WIRE_ASSET_DIR="${WIRE_ASSET_DIR}")
  gtest_discover_tests(${T_NAME}
    DISCOVERY_MODE PRE_TEST
    PROPERTIES TIMEOUT ${T_TIMEOUT} LABELS "${T_LABELS}")
endfunction()
