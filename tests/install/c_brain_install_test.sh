#!/usr/bin/env bash
# examples/c_brain (plain C on Cyclone DDS's C API) built as a user of another language builds it:
#   1. cmake --install BUILD --prefix P: P/share/swarmbox/idl/swarmbox.idl is the source tree's IDL;
#   2. examples/c_brain configured with CMAKE_PREFIX_PATH=P alone: find_package(swarmbox) gives
#      SWARMBOX_IDL_DIR, idlc generates the C types from P's IDL, warnings are errors; built and
#      installed into a prefix of its own;
#   3. the same folder configured with -DSWARMBOX_IDL=<file> and no package at all, built;
#   4. the program runs: --help exits 0, a command line without --members exits 2 with the reason.
# (The program's behaviour over DDS is c_brain_test's, tests/examples.)
# Usage: c_brain_install_test.sh BUILD_DIR SOURCE_DIR C_COMPILER
set -euo pipefail
build=$1 src=$2 cc=$3

work=$(mktemp -d "${TMPDIR:-/tmp}/swarmbox-c-brain-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { printf 'c_brain_install_test: FAIL: %s\n' "$*" >&2; exit 1; }

if ! cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1; then
  tail -n 20 "$work/install.log" >&2
  fail "cmake --install $build --prefix $prefix failed (build every target first: cmake --build $build)"
fi
idl=$prefix/share/swarmbox/idl/swarmbox.idl
cmp -s "$idl" "$src/bus/idl/swarmbox.idl" || fail "$idl is missing or differs from bus/idl/swarmbox.idl"

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache)
configure() {  # configure NAME ARGS...: examples/c_brain into $work/NAME
  local name=$1
  shift
  if ! cmake -S "$src/examples/c_brain" -B "$work/$name" -G Ninja -DCMAKE_C_COMPILER="$cc" \
       -DSWARMBOX_WERROR=ON "${launcher[@]}" "$@" >"$work/$name.configure.log" 2>&1; then
    cat "$work/$name.configure.log" >&2
    fail "examples/c_brain does not configure ($name: $*)"
  fi
  cmake --build "$work/$name" >"$work/$name.build.log" 2>&1 ||
    { tail -n 40 "$work/$name.build.log" >&2; fail "examples/c_brain does not build ($name: $*)"; }
}

# Against the package: the types come from the installed IDL.
configure package -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_INSTALL_PREFIX="$work/user"
grep -qF "$idl" "$work/package/build.ninja" || fail "idlc was not given the installed IDL $idl"
cmake --install "$work/package" >"$work/user-install.log" 2>&1 ||
  { cat "$work/user-install.log" >&2; fail "cmake --install of examples/c_brain failed"; }
brain=$work/user/bin/swarmbox_c_brain
[ -x "$brain" ] || fail "no $brain after cmake --install"

# With the IDL file alone (no SwarmBox package on the path).
cp "$idl" "$work/swarmbox.idl"
configure idl-only -DSWARMBOX_IDL="$work/swarmbox.idl"
[ -x "$work/idl-only/swarmbox_c_brain" ] || fail "no swarmbox_c_brain built from -DSWARMBOX_IDL"

"$brain" --help >"$work/help.txt" || fail "swarmbox_c_brain --help exited $?"
grep -q -- '--members' "$work/help.txt" || fail "--help does not list --members: $(cat "$work/help.txt")"
code=0
"$brain" --drone scout_1 >/dev/null 2>"$work/bad.err" || code=$?
[ "$code" -eq 2 ] || fail "without --members: exit $code, wanted 2"
grep -q -- '--members is required' "$work/bad.err" || fail "the reason is missing: $(cat "$work/bad.err")"
echo "c_brain_install_test: ok (built against $prefix and from $idl alone)"
