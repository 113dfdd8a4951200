# `cmake --install build --prefix P`: the programs, the shipped trials, the docs, and the
# orchestrator's libraries as a CMake package, so a C++ program can
#
#   find_package(swarmbox 0.1 REQUIRED)
#   target_link_libraries(my_experiment PRIVATE swarmbox::experiment swarmbox::hosts)
#
# Layout (GNUInstallDirs):
#   P/bin/swarmbox, swarmbox-physics, swarmbox-agent, swarmbox-netemd   side by side: an installed
#                                  swarmbox finds its companions next to itself (images::FindProgram)
#   P/lib/libswarmbox_*.a          common, record, docker, images, dsl, faults_model, faults, runner, hosts,
#                                  report, experiment;
#                                  brain (what a brain library links, PIC) and brain_loader
#   P/include/swarmbox/<component>/...   their public headers
#   P/lib/cmake/swarmbox/          swarmboxConfig.cmake, swarmboxConfigVersion.cmake, swarmboxTargets.cmake,
#                                  SwarmboxBrain.cmake (swarmbox_add_brain)
#   P/share/swarmbox/trials/       the shipped trials, airframes/, worlds/, faults/, experiments/
#   P/share/swarmbox/idl/          swarmbox.idl, the bus's message types (other languages generate from it)
#   P/share/doc/swarmbox/          README.md and the other top-level documents, docs/
# The DDS side (bus, physics, agent libraries) is not installed as libraries: they are the
# programs inside the images, not an API (ARCHITECTURE.md: the orchestrator never links DDS).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SWARMBOX_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/swarmbox)
set(SWARMBOX_INSTALL_TRIALSDIR ${CMAKE_INSTALL_DATADIR}/swarmbox/trials)

# swarmbox_install_library(<target> <export name>): installs a library and its public headers and
# adds it to the exported package as swarmbox::<export name>. Its PUBLIC include folders (plain
# source paths, as the component CMake files write them) become build-tree-only, and the installed
# target uses P/include instead. Call after the component's own target_include_directories().
function(swarmbox_install_library target export_name)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  set(interface_dirs "")
  foreach(dir IN LISTS dirs)
    if(dir MATCHES "^\\$<")  # already a generator expression: the component chose
      list(APPEND interface_dirs "${dir}")
      continue()
    endif()
    list(APPEND interface_dirs "$<BUILD_INTERFACE:${dir}>")
    install(DIRECTORY ${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
            COMPONENT development FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
  endforeach()
  list(APPEND interface_dirs "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")
  set_target_properties(${target} PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${interface_dirs}"
    EXPORT_NAME ${export_name})
  install(TARGETS ${target} EXPORT swarmboxTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endfunction()

# swarmbox_install_program(<target>): installs a program into P/bin and exports it as an imported
# executable swarmbox::<target> (e.g. $<TARGET_FILE:swarmbox::swarmbox-physics> in a user's build).
function(swarmbox_install_program target)
  install(TARGETS ${target} EXPORT swarmboxTargets
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endfunction()

foreach(lib common record docker images worlds faults_model dsl faults runner hosts report experiment)
  swarmbox_install_library(swarmbox_${lib} ${lib})
endforeach()
# The brain SDK (agent/brain): what a brain library links, the loader, and swarmbox_add_brain().
swarmbox_install_library(swarmbox_brain brain)
swarmbox_install_library(swarmbox_brain_loader brain_loader)
install(FILES ${PROJECT_SOURCE_DIR}/cmake/SwarmboxBrain.cmake DESTINATION ${SWARMBOX_INSTALL_CMAKEDIR}
        COMPONENT development)
foreach(program swarmbox swarmbox-physics swarmbox-agent swarmbox-netemd)
  swarmbox_install_program(${program})
endforeach()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/trials/ DESTINATION ${SWARMBOX_INSTALL_TRIALSDIR}
        COMPONENT runtime FILES_MATCHING PATTERN "*.yaml")
file(GLOB swarmbox_top_docs ${PROJECT_SOURCE_DIR}/*.md)
install(FILES ${swarmbox_top_docs} DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs
        COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples
        COMPONENT development)

# The IDL of every bus message: a program in another language generates its types from it and flies
# a drone over the offboard topics (examples/c_brain: idlc -l c). SWARMBOX_IDL_DIR in the package.
set(SWARMBOX_INSTALL_IDLDIR ${CMAKE_INSTALL_DATADIR}/swarmbox/idl)
install(FILES ${PROJECT_SOURCE_DIR}/bus/idl/swarmbox.idl DESTINATION ${SWARMBOX_INSTALL_IDLDIR}
        COMPONENT development)

install(EXPORT swarmboxTargets NAMESPACE swarmbox:: DESTINATION ${SWARMBOX_INSTALL_CMAKEDIR}
        FILE swarmboxTargets.cmake COMPONENT development)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/swarmboxConfig.cmake.in
  ${PROJECT_BINARY_DIR}/swarmboxConfig.cmake
  INSTALL_DESTINATION ${SWARMBOX_INSTALL_CMAKEDIR}
  PATH_VARS SWARMBOX_INSTALL_TRIALSDIR CMAKE_INSTALL_BINDIR)
# 0.x: a new minor version may change the API (semantic versioning's initial development).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/swarmboxConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/swarmboxConfig.cmake ${PROJECT_BINARY_DIR}/swarmboxConfigVersion.cmake
        DESTINATION ${SWARMBOX_INSTALL_CMAKEDIR} COMPONENT development)
