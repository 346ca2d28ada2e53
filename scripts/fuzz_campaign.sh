#!/usr/bin/env bash
# A long libFuzzer campaign on every core, resumable: the corpus lives in
# $FUZZ_CAMPAIGN_DIR/<target>/corpus (default build-fuzz/campaign/) and grows across runs, so a
# campaign can be stopped (Ctrl-C) and continued later from where it was.
#
#   scripts/fuzz_campaign.sh TARGET [EXECUTIONS] [WORKERS]
#     TARGET      fuzz_decoder | fuzz_structure | fuzz_mesh_readers | fuzz_repair | all
#     EXECUTIONS  total executions to run now (default 10000000), split over the workers
#     WORKERS     parallel fuzzing processes (default: nproc)
#
# Each worker is one libFuzzer job (-jobs=WORKERS -workers=WORKERS) with -runs=EXECUTIONS/WORKERS,
# sharing the corpus directory (libFuzzer re-reads new units from it). At the end the script
# prints, per target, the executions of this run, exec/s, the corpus size, the campaign total so
# far (kept in campaign.tsv beside the corpus) and any crash/timeout/oom/leak reproducers;
# it exits 1 when one was found. Build: scripts/fuzz.sh build (clang + ASan/UBSan + libFuzzer).
set -u
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TARGET="${1:?usage: fuzz_campaign.sh TARGET [EXECUTIONS] [WORKERS]}"
EXECUTIONS="${2:-10000000}"
WORKERS="${3:-$(nproc)}"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-fuzz}"
DIR="${FUZZ_CAMPAIGN_DIR:-$BUILD_DIR/campaign}"
[ "$TARGET" = all ] && TARGET="fuzz_decoder fuzz_structure fuzz_mesh_readers fuzz_repair"

BUILD_DIR="$BUILD_DIR" FUZZ_TARGETS="$TARGET" bash "$ROOT/scripts/fuzz.sh" build || exit 2

status=0
for t in $TARGET; do
  seeds="$ROOT/tests/fuzz/corpus_${t#fuzz_}"
  [ "$t" = fuzz_mesh_readers ] && seeds="$ROOT/tests/fuzz/corpus_readers"
  run="$DIR/$t"
  mkdir -p "$run/corpus" "$run/artifacts" "$run/logs"
  cp -n "$seeds"/* "$run/corpus"/ 2>/dev/null
  stamp=$(date +%Y%m%d-%H%M%S)
  logs="$run/logs/$stamp"
  mkdir -p "$logs"
  echo "== $t: $EXECUTIONS executions on $WORKERS workers, corpus $run/corpus, logs $logs"
  start=$(date +%s)
  (cd "$logs" &&
    LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$ROOT/tests/fuzz/lsan.supp:print_suppressions=0}" \
    ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}" \
    UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
    "$BUILD_DIR/tests/fuzz/$t" "$run/corpus" -jobs="$WORKERS" -workers="$WORKERS" \
      -runs=$((EXECUTIONS / WORKERS)) -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$run/artifacts/" -print_final_stats=1 >"$logs/main.log" 2>&1)
  end=$(date +%s)
  execs=$(cat "$logs"/fuzz-*.log 2>/dev/null | awk '/stat::number_of_executed_units/ {s += $2} END {print s + 0}')
  secs=$((end - start))
  units=$(ls "$run/corpus" | wc -l)
  printf '%s\t%s\t%s\t%s\n' "$stamp" "$execs" "$secs" "$units" >>"$run/campaign.tsv"
  total=$(awk -F'\t' '{s += $2} END {print s + 0}' "$run/campaign.tsv")
  echo "   $execs executions in $secs s ($((execs / (secs > 0 ? secs : 1))) exec/s), corpus $units units;" \
    "campaign total $total executions ($run/campaign.tsv)"
  if compgen -G "$run/artifacts/*" >/dev/null; then
    status=1
    for f in "$run/artifacts"/*; do echo "   FINDING: $f"; done
    grep -h -E 'ERROR: (AddressSanitizer|libFuzzer|UndefinedBehaviorSanitizer)|runtime error:|SUMMARY:' \
      "$logs"/fuzz-*.log | sort | uniq -c | head -20 | sed 's/^/   /'
  fi
done
exit $status
