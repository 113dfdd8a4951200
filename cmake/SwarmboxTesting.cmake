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
  gtest_discover_tests(${T_NAME}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
    DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT ${T_TIMEOUT})
  # List-valued properties lose their ';' on the way through gtest_discover_tests (only the first
  # label would stick), so labels and locks are set by a second include file that runs after
  # discovery, on the list of test names discovery leaves in ${T_NAME}_TESTS.
  set(label_file ${CMAKE_CURRENT_BINARY_DIR}/${T_NAME}_labels.cmake)
  set(lock_prop "")
  if(T_RESOURCE_LOCK)
    set(lock_prop " RESOURCE_LOCK \"${T_RESOURCE_LOCK}\"")
  endif()
  file(WRITE ${label_file}
    "if(DEFINED ${T_NAME}_TESTS)\n"
    "  set_tests_properties(\${${T_NAME}_TESTS} PROPERTIES LABELS \"${T_LABELS}\"${lock_prop})\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${label_file})
endfunction()
