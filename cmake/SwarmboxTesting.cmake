# swarmbox_add_test(NAME <name> SOURCES <files...> LIBS <targets...> [LABELS <labels...>]
#                   [TIMEOUT <s>] [RESOURCE_LOCK <names...>] [OPTIMIZED] [SERIAL])
# Builds one GoogleTest executable and registers each of its TEST()s with CTest
# (gtest_discover_tests), so ctest's summary counts test cases, not binaries.
# Labels: "unit" (pure logic, fast, default), "integration" (processes over the bus on loopback),
# "e2e" (real Docker engine). `ctest -L unit` runs the fast set.
# Every test labelled "unit" is also a dependency of the aggregate target swarmbox_unit_tests, so a
# sanitizer build can build just those: cmake --build build-asan --target swarmbox_unit_tests.
# A test's own sources compile at -O1: they are set-up and assertions, while the code under test
# lives in the libraries, built at the build type's level (-O2). GoogleTest's macros make test
# sources the slowest to compile (runner_test.cpp: 21.0 s at -O2 -g1, 13.3 s at -O1 -g1), and test
# sources are two thirds of the build. OPTIMIZED keeps the build type's level, for a test whose own
# sources do heavy numeric work. SERIAL (CTest RUN_SERIAL): nothing else of the suite runs beside
# the test, for the ones that time packets to a millisecond (the netns delayer tests).
include(GoogleTest)
if(NOT TARGET swarmbox_unit_tests)
  add_custom_target(swarmbox_unit_tests)
endif()

# swarmbox_test_cost(<out-var> <labels>): the CTest COST of a test with these labels. `ctest -j`
# starts the costliest tests first; without this a fresh build folder (no CTestCostData.txt yet, as
# in CI) runs tests in declaration order, and the Docker end-to-end tests, which share one
# RESOURCE_LOCK and so run one after another, came last with the second core idle beside them.
# Starting them first lets the unit and integration tests fill the other core meanwhile.
function(swarmbox_test_cost out labels)
  set(cost 0)
  if("e2e" IN_LIST labels)
    set(cost 1000)
  elseif("integration" IN_LIST labels)
    set(cost 100)
  endif()
  set(${out} ${cost} PARENT_SCOPE)
endfunction()

function(swarmbox_add_test)
  cmake_parse_arguments(T "OPTIMIZED;SERIAL" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS;RESOURCE_LOCK" ${ARGN})
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE ${T_LIBS} GTest::gtest GTest::gmock GTest::gtest_main)
  swarmbox_target_defaults(${T_NAME})
  if(NOT T_OPTIMIZED)
    target_compile_options(${T_NAME} PRIVATE $<$<CONFIG:RelWithDebInfo,Release>:-O1>)
  endif()
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
  if(T_SERIAL)
    string(APPEND lock_prop " RUN_SERIAL ON")
  endif()
  swarmbox_test_cost(cost "${T_LABELS}")
  file(WRITE ${label_file}
    "if(DEFINED ${T_NAME}_TESTS)\n"
    "  set_tests_properties(\${${T_NAME}_TESTS} PROPERTIES LABELS \"${T_LABELS}\"${lock_prop} COST ${cost})\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${label_file})
endfunction()
