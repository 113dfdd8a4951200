# swarmbox_add_test(NAME <name> SOURCES <files...> LIBS <targets...> [LABELS <labels...>]
#                   [TIMEOUT <s>] [RESOURCE_LOCK <names...>])
# Builds one GoogleTest executable and registers each of its TEST()s with CTest
# (gtest_discover_tests), so ctest's summary counts test cases, not binaries.
# Labels: "unit" (pure logic, fast, default), "integration" (processes over the bus on loopback),
# "e2e" (real Docker engine). `ctest -L unit` runs the fast set.
# Every test labelled "unit" is also a dependency of the aggregate target swarmbox_unit_tests, so a
# sanitizer build can build just those: cmake --build build-asan --target swarmbox_unit_tests.
include(GoogleTest)
if(NOT TARGET swarmbox_unit_tests)
  add_custom_target(swarmbox_unit_tests)
endif()

function(swarmbox_add_test)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS;RESOURCE_LOCK" ${ARGN})
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  swarmbox_target_defaults(${T_NAME})
  if("unit" IN_LIST T_LABELS)
    add_dependencies(swarmbox_unit_tests ${T_NAME})
  endif()
  set(props LABELS "${T_LABELS}" TIMEOUT ${T_TIMEOUT})
  if(T_RESOURCE_LOCK)
    list(APPEND props RESOURCE_LOCK "${T_RESOURCE_LOCK}")
  endif()
  gtest_discover_tests(${T_NAME}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
    DISCOVERY_TIMEOUT 60
    PROPERTIES ${props})
endfunction()
