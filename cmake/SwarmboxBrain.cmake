# swarmbox_add_brain(<name> SOURCES <files...> [LIBS <targets...>])
#
# Builds a brain library: a MODULE library lib<name>.so that swarmbox-agent loads with dlopen
# (a trial's `brain: {library: lib<name>.so, name: ...}`), linked with swarmbox::brain. The same
# function in the SwarmBox tree and for users of the installed package (find_package(swarmbox)):
#
#   find_package(swarmbox 0.1 REQUIRED)
#   swarmbox_add_brain(my_brain SOURCES my_brain.cpp)
#
# What it sets, and why (agent/brain/README.md, "ABI"):
#   - C++20 and position-independent code, as the agent is built;
#   - hidden visibility for the brain's own code (-fvisibility=hidden, inlines too): the library
#     exports only swarmbox_brain_abi_version and swarmbox_brain_registry (from swarmbox::brain),
#     so nothing of it can clash with the agent or another brain library loaded next to it;
#   - a version script exporting those two and nothing else (the C++ standard library's template
#     instantiations keep default visibility under -fvisibility=hidden: they go local too);
#   - -Wl,-Bsymbolic: what it does export binds to its own definitions, never to a same-named
#     symbol of the agent or of a library loaded before it;
#   - -Wl,-z,defs (GCC, Clang without sanitizers): an undefined symbol fails the build, not the
#     agent's dlopen at the start of a trial.
# LIBS are linked privately; a static library linked in must be position independent.
function(swarmbox_add_brain name)
  cmake_parse_arguments(B "" "" "SOURCES;LIBS" ${ARGN})
  if(NOT B_SOURCES)
    message(FATAL_ERROR "swarmbox_add_brain(${name}): SOURCES is required")
  endif()
  if(NOT TARGET swarmbox::brain)
    message(FATAL_ERROR "swarmbox_add_brain(${name}): no target swarmbox::brain (find_package(swarmbox) first)")
  endif()
  add_library(${name} MODULE ${B_SOURCES})
  target_link_libraries(${name} PRIVATE swarmbox::brain ${B_LIBS})
  set_target_properties(${name} PROPERTIES
    CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON CXX_EXTENSIONS OFF
    POSITION_INDEPENDENT_CODE ON
    CXX_VISIBILITY_PRESET hidden C_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  set(map ${CMAKE_CURRENT_BINARY_DIR}/swarmbox_brain_exports.map)
  if(NOT EXISTS ${map})
    file(WRITE ${map} "{\n  global: swarmbox_brain_abi_version; swarmbox_brain_registry;\n  local: *;\n};\n")
  endif()
  target_link_options(${name} PRIVATE -Wl,-Bsymbolic "-Wl,--version-script=${map}")
  set_property(TARGET ${name} APPEND PROPERTY LINK_DEPENDS ${map})
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" OR (CMAKE_CXX_COMPILER_ID MATCHES "Clang" AND NOT SANITIZER))
    target_link_options(${name} PRIVATE -Wl,-z,defs)
  endif()
  # Inside the SwarmBox tree: the project's warnings (and -Werror in CI).
  if(COMMAND swarmbox_target_defaults)
    swarmbox_target_defaults(${name})
  endif()
endfunction()
