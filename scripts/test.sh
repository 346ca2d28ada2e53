#!/usr/bin/env bash
# Builds everything in build-test/ and runs the whole test suite (GoogleTest + CLI end-to-end) with ctest.
# This is the project's test command (also run by .ci/run). Works from any directory.
#
# Release optimisation but with assertions enabled (no -DNDEBUG), so assert()s in the codec and in
# vcglib are checked while the tests run; then the web tests (web/test/run.sh: the WebAssembly decoder
# against the native one, the viewer in headless Chromium); then the same suite again under ASan + UBSan (build-asan/),
# the threaded tests under ThreadSanitizer (build-tsan/), then a timed libFuzzer run of each fuzz target
# (build-fuzz/; POMAR_TEST_FUZZ_SECONDS, default 20, 0 skips). Takes about 16-20 minutes from a
# fresh clone on 2 cores, the ThreadSanitizer pass included.
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"

JOBS="${POMAR_TEST_JOBS:-2}"
BUILD=build-test

bash scripts/setup.sh

echo "test: configuring $BUILD (Release, assertions on)"
cmake -S . -B "$BUILD" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O2" \
  -DPOMAR_BUILD_TESTS=ON
echo "test: building"
cmake --build "$BUILD" -j "$JOBS"

echo "test: running ctest"
ctest --test-dir "$BUILD" --output-on-failure -j "$JOBS"

# ---- web: the WebAssembly decoder and the viewer in headless Chromium -----------------------------
# web/test/run.sh builds the decoder with emscripten (build-web-test/), checks WASM decode = native
# decode bit for bit and that damaged inputs give messages (Node.js), then runs the viewer page in
# headless Chromium. About 2-3 minutes on 2 cores (the phone-emulation test included); each part is skipped with a message when
# emscripten, node or chromium is missing. POMAR_TEST_WEB=0 skips it.
if [ "${POMAR_TEST_WEB:-1}" != 0 ]; then
  JOBS="$JOBS" bash web/test/run.sh "$REPO/build-web-test" "$REPO/$BUILD/codec/pomar"
fi

# ---- ASan/UBSan pass -------------------------------------------------------------------------------
# The same suite again, built with -fsanitize=address,undefined (POMAR_SANITIZE) in build-asan/.
# POMAR_BUILD_BENCH=OFF leaves in the default target exactly what ctest runs (codec libraries, the
# pomar tool, the test executables, the MeshLab plugin and its tests when that is built).
# -O1 -g1 (ASan's recommended level; line tables give file:line in reports) compiles in about half the
# time of RelWithDebInfo's -O2 -g, and without -DNDEBUG the assert()s stay on as in the pass above.
# Any sanitizer report aborts the process, which fails its test. POMAR_TEST_SANITIZE=0 skips the pass.
# configure_sanitized DIR OPTION...: the tests in DIR at -O1 -g1, assertions on, no benchmarks,
# with the sanitizer OPTIONs (this pass and the ThreadSanitizer one below).
configure_sanitized() {
  local dir="$1"
  shift
  cmake -S . -B "$dir" -G Ninja \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DPOMAR_BUILD_TESTS=ON \
    -DPOMAR_BUILD_BENCH=OFF "$@"
}
if [ "${POMAR_TEST_SANITIZE:-1}" != 0 ]; then
  ASAN_BUILD=build-asan
  echo "test: configuring $ASAN_BUILD (ASan + UBSan, -O1, assertions on)"
  configure_sanitized "$ASAN_BUILD" -DPOMAR_SANITIZE=ON
  echo "test: building $ASAN_BUILD"
  cmake --build "$ASAN_BUILD" -j "$JOBS"

  echo "test: running ctest under ASan + UBSan"
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  LSAN_OPTIONS="suppressions=$REPO/tests/sanitizers/lsan.supp" \
    ctest --test-dir "$ASAN_BUILD" --output-on-failure -j "$JOBS"
fi

# ---- ThreadSanitizer pass on the threaded steps -----------------------------------------------------
# The decoder's threads traverse a level's clusters, then apply them, several at once
# (codec/src/decode/level_schedule.h): a data race there would not show in the outputs every time.
# The tests that run the codec on several threads are built with -fsanitize=thread (build-tsan/,
# pomar_tests only, a few minutes on 2 cores) and any report fails the test command.
# POMAR_TEST_TSAN=0 skips the pass.
if [ "${POMAR_TEST_TSAN:-1}" != 0 ]; then
  TSAN_BUILD=build-tsan
  echo "test: configuring $TSAN_BUILD (ThreadSanitizer, -O1)"
  configure_sanitized "$TSAN_BUILD" -DPOMAR_SANITIZE_THREAD=ON -DPOMAR_BUILD_MESHLAB_PLUGINS=OFF
  echo "test: building $TSAN_BUILD (pomar_tests)"
  cmake --build "$TSAN_BUILD" -j "$JOBS" --target pomar_tests
  echo "test: running the threaded tests under ThreadSanitizer"
  tsan_log="$TSAN_BUILD/threaded-tests.log"
  TSAN_OPTIONS=halt_on_error=1:abort_on_error=1 "$TSAN_BUILD/tests/pomar_tests" \
    --gtest_filter='LevelSchedule.*:DecodeThreads.*:Codec.FileDoesNotDependOnThreadCount' |
    tee "$tsan_log"
  # (A filter that matches nothing would pass: the tests run must be the ones named.)
  ran="$(grep -c '^\[       OK \]' "$tsan_log" || true)"
  if [ "$ran" -lt 9 ]; then
    echo "test: FAILED: $ran threaded tests ran under ThreadSanitizer, expected at least 9" >&2
    exit 1
  fi
fi

# ---- timed fuzz run ---------------------------------------------------------------------------------
# Each libFuzzer target (tests/fuzz/) runs for POMAR_TEST_FUZZ_SECONDS (default 20; 0 skips) from its
# seed corpus plus what earlier runs found (build-fuzz/fuzz-run/, kept between runs), built by
# scripts/fuzz.sh with clang + ASan/UBSan in build-fuzz/. A crash, sanitizer report, leak, timeout
# (> 10 s) or out-of-memory (> 2 GB) fails the test command; the reproducer path is printed. Skipped
# with a note when clang++ cannot link a libFuzzer program.
FUZZ_SECONDS="${POMAR_TEST_FUZZ_SECONDS:-20}"
if [ "$FUZZ_SECONDS" != 0 ]; then
  probe="$(mktemp -d)"
  echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char *, unsigned long) { return 0; }' \
    >"$probe/probe.cc"
  if command -v clang++ >/dev/null 2>&1 &&
    clang++ -fsanitize=fuzzer "$probe/probe.cc" -o "$probe/probe" >/dev/null 2>&1; then
    echo "test: fuzzing each target for ${FUZZ_SECONDS} s (scripts/fuzz.sh, build-fuzz/)"
    if ! JOBS="$JOBS" bash scripts/fuzz.sh "$FUZZ_SECONDS"; then
      rm -rf "$probe"
      echo "test: FAILED: the timed fuzz run found a problem or did not build (see above)" >&2
      exit 1
    fi
  else
    echo "test: clang++ with libFuzzer not available: timed fuzz run skipped"
  fi
  rm -rf "$probe"
fi

echo "test: all tests passed"
