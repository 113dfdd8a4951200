#!/usr/bin/env bash
# SwarmBox test suite: set up the machine, build everything, run every test under ctest, then the
# sanitizer stage: the unit tests again, built with AddressSanitizer and UndefinedBehaviorSanitizer.
# This is the README's test command, and all that .ci/run calls.
#   bash scripts/test.sh                 # the whole suite (unit, integration, Docker end-to-end, bench)
#   bash scripts/test.sh -L unit         # extra arguments go to the first ctest
# The configurations are CMakePresets.json's: `default` (or `ci` when CI=true: warnings are errors),
# `asan` and `tsan`; the stages below configure with `cmake --preset NAME` and may move the folder.
# Environment: BUILD_DIR (default build), JOBS (default: number of cores), SANITIZE (default
# address,undefined: the -DSANITIZER value of the sanitizer stage; "off" skips the stage),
# ASAN_BUILD_DIR (default build-asan), TSAN (default on; "off" skips the ThreadSanitizer stage),
# TSAN_BUILD_DIR (default build-tsan).
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh

BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
preset=default
[ "${CI:-}" = "true" ] && preset=ci   # warnings are errors in CI

cmake --preset "$preset" -B "$BUILD_DIR" >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"

# Sanitizer stage: AddressSanitizer + UndefinedBehaviorSanitizer on the unit tests of the code with
# the riskiest memory handling: byte-level parsers and codecs and the C APIs they wrap (libyaml and
# logfmt in common; HTTP, the 8-byte log framing, tar and JSON in docker; ELF and build contexts in
# images; packets and the delay scheduler in faults; the Raft log, message codec and WAL; the YAML
# overrides of the trial loader; the runner's log matching; Docker timestamps of the launch bench;
# the simulated radio channel (its profile parser, hashing and delivery queues); swarmbox diff's
# truth.csv/events.jsonl/result.json comparison; Raft's entry-log snapshots; a brain's JSON arguments;
# the C brain's parsing of committed entries; the MCAP recordings' records, chunks and CRCs).
# Not every unit test: on the project's 2-core machines building all of them a second time with
# ASan (the agent's Eigen-heavy flight/swarm code, the physics server, the DDS bus types) would
# roughly double the CI time. SANITIZER_TARGETS widens the set (e.g. "swarmbox_unit_tests", the
# aggregate of every unit test). Only unit-labelled tests of the built targets run: tests of
# targets not built show up unlabelled (<target>_NOT_BUILT) and are not selected; the benchmark
# smoke runs (swarmbox-bench --quick, label bench) and the plain add_test() that runs swarmbox
# validate are excluded (they run programs this stage does not build).
SANITIZE=${SANITIZE:-address,undefined}
ASAN_BUILD_DIR=${ASAN_BUILD_DIR:-build-asan}
read -r -a sanitizer_targets <<< "${SANITIZER_TARGETS:-common_test docker_unit_test images_unit_test \
faults_unit_test raft_log_test raft_message_codec_test raft_wal_storage_test raw_node_test \
dsl_trial_loader_test runner_pure_test cli_launch_timing_test channel_test report_run_diff_test \
raft_state_machine_test brain_args_test c_brain_rendezvous_test mcap_test}"

# ThreadSanitizer stage: the orchestrator's concurrent code, against the fake Docker API (the
# runner creates, starts and stops a level's containers from a pool of threads, creates later
# levels ahead while earlier ones start, and the experiment runner removes finished trials in the
# background while its slots launch the next ones), and DockerEngine's parts on their own (its
# JobQueue and LogFollowers: runner_engine_parts_test). scripts/tsan.supp names the one report from
# outside the project (a lock-order report inside libgdal, which OpenCV's image codecs load).
TSAN_BUILD_DIR=${TSAN_BUILD_DIR:-build-tsan}
tsan_targets=(runner_engine_parts_test runner_fake_docker_test experiment_test)

# The sanitizer builds compile while the suite runs, at the lowest CPU priority (nice 19): the
# Docker end-to-end tests share one lock and run one after another, many of them at real time,
# which leaves a core mostly idle for half an hour; a nice-19 build takes only what the tests
# leave (CFS weight 15 against 1024). Their output goes to a log, printed if they fail.
sanitizer_log="$BUILD_DIR/sanitizer-builds.log"
sanitizer_builds() {
  if [ "$SANITIZE" != "off" ]; then
    echo "test.sh: sanitizer build (-DSANITIZER=$SANITIZE) in $ASAN_BUILD_DIR: ${sanitizer_targets[*]}"
    cmake --preset asan -B "$ASAN_BUILD_DIR" -DSANITIZER="$SANITIZE" >/dev/null
    cmake --build "$ASAN_BUILD_DIR" -j "$JOBS" --target "${sanitizer_targets[@]}"
  fi
  if [ "${TSAN:-on}" != "off" ]; then
    echo "test.sh: ThreadSanitizer build in $TSAN_BUILD_DIR: ${tsan_targets[*]}"
    cmake --preset tsan -B "$TSAN_BUILD_DIR" >/dev/null
    cmake --build "$TSAN_BUILD_DIR" -j "$JOBS" --target "${tsan_targets[@]}"
  fi
}
stage_start=$(date +%s)
set -m   # the background job gets a process group of its own, so that one kill stops its compilers
( renice -n 19 -p "$BASHPID" >/dev/null; sanitizer_builds ) >"$sanitizer_log" 2>&1 &
sanitizer_pid=$!
set +m
trap 'kill -- "-$sanitizer_pid" 2>/dev/null || true' EXIT
echo "test.sh: the sanitizer builds run in the background at nice 19 (log: $sanitizer_log)"

ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" "$@"

if ! wait "$sanitizer_pid"; then
  echo "test.sh: the sanitizer builds failed; the end of $sanitizer_log:" >&2
  tail -n 60 "$sanitizer_log" >&2
  exit 1
fi
trap - EXIT
echo "test.sh: the sanitizer builds finished $(( $(date +%s) - stage_start )) s after the suite started"

# Warnings are not errors in the sanitizer builds: the first build already holds the code to
# -Werror, and GCC 12 with -fsanitize=address reports false -Wmaybe-uninitialized inside
# libstdc++'s <regex> (std::function in the regex compiler, seen in orchestrator/dsl/src/trial_loader.cpp).
if [ "$SANITIZE" != "off" ]; then
  stage_start=$(date +%s)
  # halt_on_error: the first report fails the test; detect_leaks: LeakSanitizer at exit.
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:strict_string_checks=1} \
  UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    ctest --test-dir "$ASAN_BUILD_DIR" --output-on-failure -j "$JOBS" -L unit \
      -LE bench -E '^ShippedTrialsValidate$'
  echo "test.sh: sanitizer tests took $(( $(date +%s) - stage_start )) s"
fi
if [ "${TSAN:-on}" != "off" ]; then
  stage_start=$(date +%s)
  TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:suppressions=$PWD/scripts/tsan.supp} \
    ctest --test-dir "$TSAN_BUILD_DIR" --output-on-failure -j "$JOBS" -L unit \
      -LE bench -E '^ShippedTrialsValidate$'
  echo "test.sh: ThreadSanitizer tests took $(( $(date +%s) - stage_start )) s"
fi
