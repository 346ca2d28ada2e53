#!/usr/bin/env bash
# Build the libFuzzer targets (tests/fuzz/) with clang + ASan/UBSan and run each one.
#   scripts/fuzz.sh [SECONDS]     # seconds per target, default 60
# Environment: BUILD_DIR (default build-fuzz), FUZZ_TARGETS (default: all four), JOBS.
# Long campaigns on both cores with a resumable corpus: scripts/fuzz_campaign.sh.
# Exits non-zero if a fuzzer found a crash / timeout / OOM; the reproducer paths are printed.
set -u
SECONDS_PER_TARGET="${1:-60}"   # "build" only builds the targets
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-fuzz}"
TARGETS="${FUZZ_TARGETS:-fuzz_decoder fuzz_structure fuzz_mesh_readers fuzz_repair}"

echo "== configure $BUILD_DIR (clang, ASan+UBSan+libFuzzer)"
CC=clang CXX=clang++ cmake -G Ninja -S "$ROOT" -B "$BUILD_DIR" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOMAR_BUILD_FUZZERS=ON -DPOMAR_SANITIZE=ON \
  -DPOMAR_BUILD_TESTS=OFF -DPOMAR_BUILD_BENCH=OFF -DPOMAR_BUILD_MESHLAB_PLUGINS=OFF >/dev/null || exit 2
echo "== build"
cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target $TARGETS || exit 2
[ "$SECONDS_PER_TARGET" = build ] && exit 0

status=0
for t in $TARGETS; do
  case "$t" in
    fuzz_decoder) seeds="$ROOT/tests/fuzz/corpus_decoder" ;;
    fuzz_structure) seeds="$ROOT/tests/fuzz/corpus_structure" ;;
    fuzz_mesh_readers) seeds="$ROOT/tests/fuzz/corpus_readers" ;;
    fuzz_repair) seeds="$ROOT/tests/fuzz/corpus_repair" ;;
    *) seeds="" ;;
  esac
  run="$BUILD_DIR/fuzz-run/$t"
  corpus="$run/corpus"          # writable copy: the checked-in seeds are never modified
  artifacts="$run/artifacts/"
  mkdir -p "$corpus" "$artifacts"
  [ -n "$seeds" ] && cp -n "$seeds"/* "$corpus"/ 2>/dev/null
  log="$run/fuzz.log"
  echo "== $t: ${SECONDS_PER_TARGET}s, corpus $corpus, log $log"
  start=$(date +%s)
  LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$ROOT/tests/fuzz/lsan.supp:print_suppressions=0}" \
  ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}" \
  UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
  "$BUILD_DIR/tests/fuzz/$t" "$corpus" \
    -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$artifacts" -print_final_stats=1 >"$log" 2>&1
  rc=$?
  end=$(date +%s)
  execs=$(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}')
  eps=$(grep -m1 'stat::average_exec_per_sec' "$log" | awk '{print $2}')
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  echo "   exit $rc, $((end - start)) s, executions ${execs:-?}, exec/s ${eps:-?}"
  echo "   last status: ${last:-?}"
  if [ $rc -ne 0 ]; then
    status=1
    grep -E 'ERROR: (AddressSanitizer|libFuzzer|UndefinedBehaviorSanitizer)|runtime error:|SUMMARY:|Test unit written to|ALARM|out-of-memory' "$log" | head -20 | sed 's/^/   /'
    for f in "$artifacts"*; do [ -e "$f" ] && echo "   CRASH FILE: $f"; done
  fi
done
exit $status
