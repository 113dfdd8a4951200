# Warnings, sanitizers and the compiler launcher for every SwarmBox target, set in one place.
# Usage: swarmbox_target_defaults(<target>) on every library and executable we own (a component's
# library through swarmbox_add_library(), which calls it).
# Generated code (idlc, fastddsgen) gets swarmbox_generated_defaults() instead: no warnings of ours.

# ccache, when installed, as the compiler launcher (objects are reused across build folders and
# worktrees). A launcher given on the command line or in a preset wins; SWARMBOX_CCACHE=OFF opts out.
option(SWARMBOX_CCACHE "Use ccache as the compiler launcher when it is installed" ON)
find_program(CCACHE ccache)
if(SWARMBOX_CCACHE AND CCACHE)
  foreach(lang C CXX)
    if(NOT CMAKE_${lang}_COMPILER_LAUNCHER)
      set(CMAKE_${lang}_COMPILER_LAUNCHER ${CCACHE})
    endif()
  endforeach()
endif()

# Debug information: RelWithDebInfo objects carry line tables only (-g1). Backtraces, perf and the
# sanitizers' reports keep function, file and line; what -g adds (variables and types, for gdb) made a
# test object 16x bigger and its compile about 30% slower (tests/orchestrator/runner/runner_test.cpp:
# 28.0 s, 13.2 MB at -O2 -g; 21.0 s, 3.6 MB at -O2 -g1; GCC 12). SWARMBOX_DEBUG_LEVEL=2 gives it back.
set(SWARMBOX_DEBUG_LEVEL 1 CACHE STRING "-g level of RelWithDebInfo builds (1: line tables, 2: full)")
add_compile_options($<$<CONFIG:RelWithDebInfo>:-g${SWARMBOX_DEBUG_LEVEL}>)

set(SWARMBOX_WARNINGS -Wall -Wextra -Wshadow -Wconversion -Wsign-conversion -Wnon-virtual-dtor
    -Wold-style-cast -Woverloaded-virtual -Wnull-dereference -Wimplicit-fallthrough)
if(SWARMBOX_WERROR)
  list(APPEND SWARMBOX_WARNINGS -Werror)
endif()

if(SANITIZER)
  message(STATUS "SwarmBox: building with -fsanitize=${SANITIZER}")
  add_compile_options(-fsanitize=${SANITIZER} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${SANITIZER})
endif()

function(swarmbox_target_defaults target)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    return()
  endif()
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:CXX>:${SWARMBOX_WARNINGS}>)
endfunction()

# swarmbox_embed_file(<input> <output.cpp> <symbol> <namespace> <comment>) generates output.cpp
# at build time, defining `const unsigned char symbol[]` (input's bytes, plus a NUL) and
# `const std::size_t symbolSize` in namespace (cmake/SwarmboxEmbed.cmake): a file compiled into a
# library, regenerated whenever it changes.
function(swarmbox_embed_file input output symbol namespace comment)
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${input} -DOUTPUT=${output} -DSYMBOL=${symbol} -DNAMESPACE=${namespace}
            -P ${PROJECT_SOURCE_DIR}/cmake/SwarmboxEmbed.cmake
    DEPENDS ${input} ${PROJECT_SOURCE_DIR}/cmake/SwarmboxEmbed.cmake
    COMMENT "${comment}"
    VERBATIM)
endfunction()

# swarmbox_add_library(<name> <add_library arguments>... [LINK <target_link_libraries arguments>...])
# declares a component's library swarmbox_<name> and its alias swarmbox::<name>, with the
# component's include/ folder as its public headers, its links and swarmbox_target_defaults().
# What a component needs besides (a private include folder, system includes, properties) it adds
# to swarmbox_<name> after the call.
function(swarmbox_add_library name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "LINK")
  set(target swarmbox_${name})
  add_library(${target} ${arg_UNPARSED_ARGUMENTS})
  add_library(swarmbox::${name} ALIAS ${target})
  target_include_directories(${target} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  if(arg_LINK)
    target_link_libraries(${target} ${arg_LINK})
  endif()
  swarmbox_target_defaults(${target})
endfunction()

function(swarmbox_generated_defaults target)
  target_compile_options(${target} PRIVATE -w)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
