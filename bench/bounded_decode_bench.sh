#!/usr/bin/env bash
# A full decode in bounded memory against the whole decode, on a streamed scan-like mesh
# (pomar_gen_mesh scan): peak RSS (GNU time %M) and wall time of each, the regions, and
# whether the two PLY files are identical (bench/README.md, "Memory").
#
#   bash bench/bounded_decode_bench.sh BUILD_DIR VERTICES LIMIT [WORK_DIR]
#
# e.g. bash bench/bounded_decode_bench.sh build-test 2000000 128M. LIMIT is pomar decode
# --max-memory's SIZE; the decodes run on one thread. WORK_DIR (default: a temporary folder,
# removed afterwards) needs about 60 bytes per vertex of free disk.
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: $0 BUILD_DIR VERTICES LIMIT [WORK_DIR]" >&2; exit 2; }
BUILD=$1 N=$2 LIMIT=$3
POMAR=$BUILD/codec/pomar GEN=$BUILD/bench/pomar_gen_mesh
if [ $# -ge 4 ]; then
  WORK=$4
  mkdir -p "$WORK"
else
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/pomar-bounded.XXXXXX")
  trap 'rm -rf "$WORK"' EXIT
fi
measure() { # measure LABEL CMD...: prints LABEL, peak MiB, seconds
  local label=$1
  shift
  /usr/bin/time -f "%M %e" -o "$WORK/time" "$@" >"$WORK/out" 2>"$WORK/err" || { cat "$WORK/err" >&2; exit 1; }
  read -r kib secs <"$WORK/time"
  printf '%-28s peak %8.1f MiB  %8.2f s\n' "$label" "$(echo "$kib / 1024" | bc -l)" "$secs"
}
measure "generate ($N)" "$GEN" scan "$N" "$WORK/scan.ply"
cat "$WORK/out"
measure "encode" "$POMAR" encode "$WORK/scan.ply" "$WORK/scan.pomar" -q
"$POMAR" info "$WORK/scan.pomar" | head -1
rm -f "$WORK/scan.ply"
measure "decode (whole)" "$POMAR" decode "$WORK/scan.pomar" "$WORK/whole.ply" --threads 1 --max-memory none -q
measure "decode --max-memory $LIMIT" "$POMAR" decode "$WORK/scan.pomar" "$WORK/bounded.ply" --threads 1 --max-memory "$LIMIT"
cat "$WORK/out"
cmp -s "$WORK/whole.ply" "$WORK/bounded.ply" && echo "identical PLY files" || { echo "the PLY files differ"; exit 1; }
