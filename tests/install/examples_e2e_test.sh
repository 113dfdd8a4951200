#!/usr/bin/env bash
# examples/ built against the installed package, as a user builds it, and run on the local engine:
#   1. cmake --install BUILD --prefix P; examples/ configured with CMAKE_PREFIX_PATH=P alone
#      (find_package(swarmbox)) and built;
#   2. hover_experiment (hover_grid.yaml in C++) runs code aa, 2 repetitions, on the local engine;
#   3. the installed `swarmbox experiment` runs the same trials from P/share/.../hover_grid.yaml;
#   4. both folders have the same shape: results.csv (same header, same trial ids, codes, factor
#      levels, repetitions, seeds and outcomes), report.html, experiment.json, plots/, and the same
#      files in each trial folder.
# Usage: examples_e2e_test.sh BUILD_DIR SOURCE_DIR CXX_COMPILER
set -euo pipefail
build=$1 src=$2 cxx=$3

work=$(mktemp -d "${TMPDIR:-/tmp}/swarmbox-examples-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
fail() { printf 'examples_e2e_test: FAIL: %s\n' "$*" >&2; exit 1; }
step() { printf 'examples_e2e_test: %s (%s s)\n' "$*" "$SECONDS"; }

if ! cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1; then
  tail -n 20 "$work/install.log" >&2
  fail "cmake --install $build --prefix $prefix failed (build every target first: cmake --build $build)"
fi
step "installed into $prefix"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if ! cmake -S "$src/examples" -B "$work/examples-build" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" \
     -DCMAKE_CXX_COMPILER="$cxx" "${launcher[@]}" >"$work/configure.log" 2>&1; then
  cat "$work/configure.log" >&2
  fail "examples/ does not configure against $prefix"
fi
cmake --build "$work/examples-build" >"$work/build.log" 2>&1 ||
  { tail -n 40 "$work/build.log" >&2; fail "examples/ does not build against $prefix"; }
step "examples/ built against the package"

mkdir "$work/cwd"
cd "$work/cwd"
run() { env -u SWARMBOX_BIN_DIR PATH=/usr/bin:/bin "$@"; }
run "$work/examples-build/hover_experiment" --out "$work/cpp" --filter aa --slots 2 ||
  fail "hover_experiment exited $?"
step "hover_experiment done"
run "$prefix/bin/swarmbox" experiment "$prefix/share/swarmbox/trials/experiments/hover_grid.yaml" \
  --out "$work/yaml" --filter aa --hosts 'local?slots=2' 2>"$work/yaml.err" ||
  { tail -n 20 "$work/yaml.err" >&2; fail "swarmbox experiment exited non-zero"; }
step "swarmbox experiment done"

for out in cpp yaml; do
  for f in results.csv report.html experiment.json plots; do
    [ -e "$work/$out/$f" ] || fail "$out: no $f"
  done
done
trials() { find "$1" -mindepth 2 -maxdepth 2 -name result.json -printf '%h\n' | xargs -rn1 basename | sort; }
[ "$(trials "$work/cpp")" = "$(printf 'hover-aa-r1\nhover-aa-r2')" ] ||
  fail "hover_experiment's trial folders: $(trials "$work/cpp" | tr '\n' ' ')"
[ "$(trials "$work/cpp")" = "$(trials "$work/yaml")" ] ||
  fail "trial folders differ: $(trials "$work/cpp" | tr '\n' ' ') vs $(trials "$work/yaml" | tr '\n' ' ')"
for t in $(trials "$work/cpp"); do
  a=$(cd "$work/cpp/$t" && find . -type f | sort)
  b=$(cd "$work/yaml/$t" && find . -type f | sort)
  [ "$a" = "$b" ] || { diff <(echo "$a") <(echo "$b") >&2; fail "$t: the trial folders hold different files"; }
done
# results.csv: the same header, and the same plan and outcome columns (everything before host,
# plus the outcome) in the same rows; the measured columns (times, metrics) may differ.
[ "$(head -n1 "$work/cpp/results.csv")" = "$(head -n1 "$work/yaml/results.csv")" ] ||
  fail "results.csv headers differ: $(head -n1 "$work/cpp/results.csv") vs $(head -n1 "$work/yaml/results.csv")"
plan_columns() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "host") h = i; if ($i == "outcome") o = i } }
           { line = ""; for (i = 1; i < h; i++) line = line $i ","; print line $o }' "$1"
}
[ "$(plan_columns "$work/cpp/results.csv")" = "$(plan_columns "$work/yaml/results.csv")" ] ||
  { diff <(plan_columns "$work/cpp/results.csv") <(plan_columns "$work/yaml/results.csv") >&2
    fail "results.csv rows differ in the plan or outcome columns"; }
[ "$(wc -l <"$work/cpp/results.csv")" -eq 3 ] || fail "results.csv of hover_experiment has not 2 rows"
grep -q ',success$' <(plan_columns "$work/cpp/results.csv") || fail "no trial succeeded: $(cat "$work/cpp/results.csv")"
step "ok: $(plan_columns "$work/cpp/results.csv" | tail -n +2 | tr '\n' ' ')"
