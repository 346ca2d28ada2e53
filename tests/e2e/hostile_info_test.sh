#!/usr/bin/env bash
# pomar info on hostile files under 1 MB (bench/hostile_files.cpp, `crafted`: huge claimed
# counts, zero-filled base blocks, 2^31 vertices, section tables at and past their limit,
# a zeroed or misaligned cluster index; every checksum right): `info`, `info --json` and
# `info --check` each stay under 64 MB of peak RSS and exit 4 (a damaged file; `info` and
# `info --json` of a file whose header and global part are consistent: 0), one line on
# stderr, no crash; `decode --max-memory 64M` refuses them (4, or 7 for counts that need
# more memory), and a decode that runs out of memory exits 7.
# Usage: hostile_info_test.sh POMAR POMAR_HOSTILE_FILES SAMPLES_DIR
set -u
# About 10 s of CPU; each command is capped at 120 s of CPU time (ulimit -t, which the
# machine's load does not stretch; ctest's TIMEOUT is a backstop for a hang).
ulimit -t 120
POMAR=$1
CRAFT=$2
SAMPLES=$3
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}

"$POMAR" encode "$SAMPLES/bunny.ply" "$TMP/c.pomar" -q || fail "encode"
"$POMAR" encode "$SAMPLES/bunny.ply" "$TMP/p.pomar" -q --progressive || fail "encode --progressive"
mkdir "$TMP/crafted"
names=$("$CRAFT" crafted "$TMP/c.pomar" "$TMP/p.pomar" "$TMP/crafted") || fail "crafted files"
[ "$(echo "$names" | wc -l)" -ge 10 ] || fail "expected at least 10 crafted files, got: $names"

# Exit status and peak RSS (KiB) of a command run as a child of its own.
probe() {
  python3 -c '
import resource, subprocess, sys
r = subprocess.run(sys.argv[2:], stdout=subprocess.DEVNULL, stderr=open(sys.argv[1], "w"))
print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)' "$TMP/err" "$@"
}

# Files whose header, base mesh and sections hold together (their levels do not decode to
# what the header claims, which only a decode finds): info describes them and
# info --check finds every checksum right (exit 0). A misaligned cluster index is
# consistent too, but its blocks fail their checks: info --check lists them (exit 4).
consistent=" huge_counts big_base_attributes big_base_wedges shifted_index "
# Checked apart (below): info --check builds the base mesh of a file with wedge texture
# coordinates to resolve them, so it needs what a decode of the base mesh needs.
base_decoded=" big_base_wedges "
blocks_fail=" shifted_index "
checked=0
for name in $names; do
  f="$TMP/crafted/$name.pomar"
  size=$(stat -c %s "$f")
  [ "$size" -lt 1000000 ] || fail "$name: $size bytes, not under 1 MB"
  for args in "" "--json" "--check"; do
    case "$args$base_decoded" in "--check"*" $name "*) continue ;; esac
    want=4
    case $consistent in *" $name "*) want=0 ;; esac
    case "$args$blocks_fail" in "--check"*" $name "*) want=4 ;; esac
    read -r status rss < <(probe "$POMAR" info "$f" $args)
    [ "$status" = "$want" ] ||
      fail "pomar info $args $name: exit $status, expected $want: $(cat "$TMP/err")"
    [ "$rss" -lt 65536 ] || fail "pomar info $args $name: peak RSS $rss KiB (64 MB is the bound)"
    if [ "$want" != 0 ] && [ "$(grep -c . "$TMP/err")" != 0 -o "$args" != "--check" ]; then
      [ "$(grep -c . "$TMP/err")" -eq 1 ] || fail "pomar info $name: not one line on stderr: $(cat "$TMP/err")"
      grep -q "^pomar: error: " "$TMP/err" || fail "pomar info $name: $(cat "$TMP/err")"
    fi
    echo "ok: info $args $name: exit $status, peak RSS $rss KiB"
    checked=$((checked + 1))
  done
  read -r status rss < <(probe "$POMAR" decode "$f" "$TMP/out.ply" --max-memory 64M)
  case $status in
  4 | 7) ;;
  *) fail "pomar decode $name: exit $status, expected 4 or 7: $(cat "$TMP/err")" ;;
  esac
  echo "ok: decode $name: exit $status, peak RSS $rss KiB"
done
# info --check of a base mesh of 3 million vertices with wedge texture coordinates (878 KB):
# its peak stays under the memory check's estimate for decoding the base mesh, and an
# address space below that estimate is refused before the base mesh is built (exit 7).
f="$TMP/crafted/big_base_wedges.pomar"
status=$( (ulimit -v 200000; "$POMAR" info --check "$f" >/dev/null 2>"$TMP/err"); echo $?)
[ "$status" = 7 ] || fail "info --check big_base_wedges under 200 MB: exit $status, expected 7: $(cat "$TMP/err")"
grep -q "^pomar: error: not enough memory to decode 3,000,000 vertices" "$TMP/err" ||
  fail "info --check big_base_wedges under 200 MB: $(cat "$TMP/err")"
need=$(sed -n 's/.*needs about \([0-9.]*\) MiB.*/\1/p' "$TMP/err")
[ -n "$need" ] || fail "info --check big_base_wedges: no estimate in MiB: $(cat "$TMP/err")"
read -r status rss < <(probe "$POMAR" info "$f" --check)
[ "$status" = 0 ] || fail "pomar info --check big_base_wedges: exit $status: $(cat "$TMP/err")"
python3 -c 'import sys; sys.exit(0 if float(sys.argv[1]) <= float(sys.argv[2]) * 1024 else 1)' "$rss" "$need" ||
  fail "pomar info --check big_base_wedges: peak RSS $rss KiB over the estimate of $need MiB"
echo "ok: info --check big_base_wedges: refused under 200 MB (needs about $need MiB), else exit 0 with peak RSS $rss KiB"
# An explicit limit below the estimate refuses it the same way, naming the limit.
status=$("$POMAR" info --check "$f" --max-memory 64M >/dev/null 2>"$TMP/err"; echo $?)
[ "$status" = 7 ] || fail "info --check --max-memory 64M big_base_wedges: exit $status, expected 7"
grep -q "the limit is 64.0 MiB; set the limit with pomar --max-memory" "$TMP/err" ||
  fail "info --check --max-memory 64M big_base_wedges: $(cat "$TMP/err")"
echo "ok: info --check --max-memory 64M refuses big_base_wedges, naming the limit"

# Memory running out (no check, a 400 MB address space) is the memory kind's status, 7,
# never 1: the base mesh of big_base_attributes needs more.
status=$( (ulimit -v 400000; "$POMAR" decode "$TMP/crafted/big_base_attributes.pomar" "$TMP/out.ply" \
  --max-memory none 2>"$TMP/err"); echo $?)
[ "$status" = 7 ] || fail "decode out of memory: exit $status, expected 7: $(cat "$TMP/err")"
grep -q "^pomar: error: out of memory" "$TMP/err" || fail "decode out of memory: $(cat "$TMP/err")"
[ ! -e "$TMP/out.ply" ] || fail "decode out of memory left an output"
echo "ok: decode out of memory: exit 7"
echo "PASS: $checked info runs on hostile files, each under 64 MB"
