#!/usr/bin/env bash
# The installed package, as a user gets it from `cmake --install BUILD --prefix P`:
#   - the programs, libraries, headers, CMake package files, shipped trials and docs are there;
#   - the installed headers are usable from P/include alone (public headers include only public
#     headers: every one of them compiles in one translation unit with just -I P/include);
#   - the installed swarmbox runs from an empty folder with a PATH that holds none of the build tree
#     and no SWARMBOX_BIN_DIR: --help, `validate` on P/share/swarmbox/trials/sar_search.yaml, and
#     `compose`, which packs the images of P/bin/swarmbox-physics and P/bin/swarmbox-agent (no
#     engine needed): found beside swarmbox (the tags equal those of --physics-bin/--agent-bin
#     P/bin/...), and a missing companion is reported with the place looked in;
#   - the brain SDK: examples/brains/rendezvous builds against P alone (find_package(swarmbox),
#     swarmbox_add_brain), its library exports exactly the three entry points, and a program on the
#     installed loader (brain_loader_check/) loads it and steps it once (take-off first).
# Usage: install_test.sh BUILD_DIR SOURCE_DIR CXX_COMPILER
set -euo pipefail
build=$1 src=$2 cxx=$3

work=$(mktemp -d "${TMPDIR:-/tmp}/swarmbox-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { printf 'install_test: FAIL: %s\n' "$*" >&2; exit 1; }

if ! cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1; then
  tail -n 20 "$work/install.log" >&2
  fail "cmake --install $build --prefix $prefix failed (build every target first: cmake --build $build)"
fi

for f in bin/swarmbox bin/swarmbox-physics bin/swarmbox-agent bin/swarmbox-netemd \
         lib/cmake/swarmbox/swarmboxConfig.cmake lib/cmake/swarmbox/swarmboxConfigVersion.cmake \
         lib/cmake/swarmbox/swarmboxTargets.cmake \
         include/swarmbox/common/result.hpp include/swarmbox/dsl/trial_loader.hpp \
         include/swarmbox/experiment/experiment_runner.hpp include/swarmbox/hosts/host.hpp \
         include/swarmbox/brain/brain.hpp include/swarmbox/brain/loader.hpp \
         include/swarmbox/brain/args.hpp lib/cmake/swarmbox/SwarmboxBrain.cmake \
         share/doc/swarmbox/README.md share/doc/swarmbox/examples/CMakeLists.txt; do
  [ -e "$prefix/$f" ] || fail "missing $prefix/$f"
done
for lib in common record docker images dsl faults runner hosts report experiment brain brain_loader; do
  [ -f "$prefix/lib/libswarmbox_$lib.a" ] || fail "missing $prefix/lib/libswarmbox_$lib.a"
done
# Every shipped trial, airframe, world, fault trial and experiment.
count=0
while IFS= read -r -d '' f; do
  rel=${f#"$src/trials/"}
  [ -f "$prefix/share/swarmbox/trials/$rel" ] || fail "shipped trial file $rel not installed"
  count=$((count + 1))
done < <(find "$src/trials" -name '*.yaml' -print0)
[ "$count" -gt 10 ] || fail "only $count trial files found under $src/trials"

# Public headers include only public headers: all of them, from P/include alone.
{
  while IFS= read -r -d '' h; do printf '#include "%s"\n' "${h#"$prefix/include/"}"; done \
    < <(find "$prefix/include" -name '*.hpp' -print0 | sort -z)
} >"$work/all_headers.cpp"
"$cxx" -std=c++20 -fsyntax-only -I "$prefix/include" "$work/all_headers.cpp" 2>"$work/headers.log" ||
  { cat "$work/headers.log" >&2; fail "the installed headers do not compile from $prefix/include alone"; }

# The brain SDK: the example brain and a loader program, built against P alone.
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
for project in "$src/examples/brains/rendezvous" "$src/tests/install/brain_loader_check"; do
  out=$work/build-$(basename "$project")
  cmake -S "$project" -B "$out" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" \
    "${launcher[@]}" >"$work/brain-configure.log" 2>&1 ||
    { cat "$work/brain-configure.log" >&2; fail "$project does not configure against $prefix"; }
  cmake --build "$out" >"$work/brain-build.log" 2>&1 ||
    { tail -n 40 "$work/brain-build.log" >&2; fail "$project does not build against $prefix"; }
done
brain_lib=$work/build-rendezvous/librendezvous_brain.so
[ -f "$brain_lib" ] || fail "no $brain_lib"
exports=$(nm -D --defined-only "$brain_lib" | awk '{print $3}' | sort | tr '\n' ' ')
[ "$exports" = "swarmbox_brain_abi_version swarmbox_brain_cxx_library swarmbox_brain_registry " ] ||
  fail "librendezvous_brain.so exports more or less than the three entry points: $exports"
answer=$("$work/build-brain_loader_check/brain_loader_check" "$brain_lib" rendezvous) ||
  fail "the installed loader did not load $brain_lib"
[ "$answer" = "takeoff(10) rendezvous/takeoff" ] || fail "the rendezvous brain's first answer: $answer"
if "$work/build-brain_loader_check/brain_loader_check" "$brain_lib" nothing 2>"$work/brain-unknown.err"; then
  fail "loading brain 'nothing' succeeded"
fi
grep -qF 'no brain named "nothing" in the library; it has: rendezvous' "$work/brain-unknown.err" ||
  { cat "$work/brain-unknown.err" >&2; fail "the unknown brain's error does not list the library's brains"; }

# The installed programs, away from the build tree.
mkdir "$work/cwd"
cd "$work/cwd"
run() { env -u SWARMBOX_BIN_DIR PATH=/usr/bin:/bin "$@"; }
run "$prefix/bin/swarmbox" --help >"$work/help.txt" || fail "swarmbox --help exited $?"
grep -q 'validate' "$work/help.txt" || fail "swarmbox --help does not list validate"
run "$prefix/bin/swarmbox" validate "$prefix/share/swarmbox/trials/sar_search.yaml" ||
  fail "swarmbox validate $prefix/share/swarmbox/trials/sar_search.yaml exited $?"

trial=$prefix/share/swarmbox/trials/smoke.yaml
run "$prefix/bin/swarmbox" compose "$trial" >"$work/found.yaml" 2>"$work/found.err" ||
  { cat "$work/found.err" >&2; fail "swarmbox compose (companions found beside swarmbox) exited non-zero"; }
run "$prefix/bin/swarmbox" compose "$trial" --physics-bin "$prefix/bin/swarmbox-physics" \
  --agent-bin "$prefix/bin/swarmbox-agent" >"$work/explicit.yaml" ||
  fail "swarmbox compose with --physics-bin/--agent-bin exited non-zero"
[ "$(grep -c 'image: ' "$work/found.yaml")" -ge 2 ] || fail "no physics and agent images in the compose file"
cmp -s "$work/found.yaml" "$work/explicit.yaml" ||
  { diff "$work/found.yaml" "$work/explicit.yaml" >&2; fail "the companions found are not $prefix/bin's"; }

mv "$prefix/bin/swarmbox-physics" "$work/swarmbox-physics.away"
if run "$prefix/bin/swarmbox" compose "$trial" >/dev/null 2>"$work/missing.err"; then
  fail "swarmbox compose succeeded without $prefix/bin/swarmbox-physics"
fi
grep -qF "$prefix/bin/swarmbox-physics" "$work/missing.err" ||
  { cat "$work/missing.err" >&2; fail "the error does not name $prefix/bin/swarmbox-physics"; }
echo "install_test: ok ($count trial files, $(find "$prefix/include" -name '*.hpp' | wc -l) headers, prefix $prefix)"
