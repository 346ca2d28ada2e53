#!/usr/bin/env bash
# Every error path of the pomar tool and the exit status it gives (README "Exit codes";
# codec/tool/exit_codes.h maps pomar::Error kinds to them). Each check runs one command and
# asserts its status and the words that name the problem (on stderr, or stdout for
# info --check's listing).
#
#   bash tests/e2e/exit_codes_test.sh POMAR SAMPLES_DIR
#
# Not reachable from any input, so not here: 70 (a broken invariant of the codec, a bug)
# and 1 (an exception that is not a pomar::Error, e.g. std::bad_alloc).
set -u
POMAR=$(realpath "${1:?usage: exit_codes_test.sh POMAR SAMPLES_DIR}") || exit 1
SAMPLES=$(cd "${2:?usage: exit_codes_test.sh POMAR SAMPLES_DIR}" && pwd) || exit 1
EDIT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../support" && pwd)/pomar_file.py"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
failures=0 checks=0
LIMIT_FSIZE= # set: the command runs under ulimit -f (in 512-byte blocks)

# expect STATUS WORDS ARGS...: `pomar ARGS` exits with STATUS and its output holds WORDS
# (a fixed string; "" for none).
expect() {
  local want=$1 words=$2
  shift 2
  checks=$((checks + 1))
  if [ -n "$LIMIT_FSIZE" ]; then
    (ulimit -f "$LIMIT_FSIZE" && exec "$POMAR" "$@") >"$W/out" 2>"$W/err"
  else
    "$POMAR" "$@" >"$W/out" 2>"$W/err"
  fi
  local rc=$?
  if [ "$rc" -ne "$want" ]; then
    printf 'FAIL: expected exit %s, got %s: pomar %s\n' "$want" "$rc" "$*"
    head -n 5 "$W/err" | sed 's/^/    /'
    failures=$((failures + 1))
  elif [ -n "$words" ] && ! cat "$W/err" "$W/out" | grep -qF -- "$words"; then
    printf 'FAIL: exit %s as expected but the output does not say "%s": pomar %s\n' \
      "$want" "$words" "$*"
    head -n 5 "$W/err" | sed 's/^/    /'
    failures=$((failures + 1))
  else
    printf 'ok %3s  pomar %s\n' "$want" "$*"
  fi
}
# check WHAT COMMAND...: a condition on the files a failing command left.
check() {
  local what=$1
  shift
  checks=$((checks + 1))
  if "$@"; then printf 'ok      %s\n' "$what"; else
    printf 'FAIL: %s\n' "$what"
    failures=$((failures + 1))
  fi
}
edit() { python3 "$EDIT" "$@" || { echo "FAIL: cannot prepare a file: $*"; exit 1; }; }

# ---- inputs ----------------------------------------------------------------------------------
cd "$W" || exit 1
BUNNY=$SAMPLES/bunny.ply
cp "$SAMPLES"/textured_sphere.obj "$SAMPLES"/textured_sphere.mtl "$SAMPLES"/textured_sphere.png .
"$POMAR" encode "$BUNNY" b.pomar -q --clusters 40 || exit 1
"$POMAR" encode "$BUNNY" p.pomar -q --progressive || exit 1
# The textured sphere embedded: sections ATTR, TEXI, MATL and LSLS.
"$POMAR" encode --embed-textures textured_sphere.obj tex.pomar -q || exit 1
"$POMAR" info --json tex.pomar >tex.json || exit 1
"$POMAR" info --json b.pomar >b.json || exit 1
"$POMAR" info --json p.pomar >p.json || exit 1
for s in ATTR MATL TEXI LSLS; do
  grep -q "\"name\": \"$s\"" tex.json || { echo "FAIL: tex.pomar has no $s section"; exit 1; }
done
python3 - b.pomar p.pomar b.json p.json <<'PY' || exit 1
import json, sys
b, p = open(sys.argv[1], "rb").read(), open(sys.argv[2], "rb").read()
bi, pi = json.load(open(sys.argv[3])), json.load(open(sys.argv[4]))
open("garbage.pomar", "wb").write(bytes(range(256)) * 8)
open("truncated.pomar", "wb").write(b[: bi["header_bytes"] + bi["base_bytes"] // 2])
d = bytearray(b); d[20] ^= 0x01; open("header.pomar", "wb").write(d)  # under the header checksum
d = bytearray(p); d[-10] ^= 0x20; open("level.pomar", "wb").write(d)  # the last level's block
d = bytearray(b); d[-10] ^= 0x20; open("cluster.pomar", "wb").write(d)  # the last cluster's block
PY
printf 'garbage\n' >garbage.ply
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n' >truncated.ply
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' >bad_index.obj
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n' >truncated.off
printf 'solid x\nfacet normal 0 0 1\n' >short.stl
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 nan 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n' >nan_normal.ply
mkdir folder textures_missing
cp textured_sphere.obj textured_sphere.mtl textures_missing/
echo "a file" >plain_file
for s in ATTR MATL TEXI LSLS; do
  edit tex.json tex.pomar "flip_$s.pomar" flip-section "$s"     # bit rot: checksum fails
  edit tex.json tex.pomar "cut_$s.pomar" section-cut "$s" 3     # checksums right, body short
done
for s in ATTR MATL TEXI; do
  edit tex.json tex.pomar "v99_$s.pomar" section-byte "$s" 0 99 # section version 99
done
edit tex.json tex.pomar v9.pomar version 9
edit tex.json tex.pomar unknown_section.pomar section-tag MATL MATX # required, unknown

# ---- the command line (CLI11's own statuses: README "other non-zero values") ------------------
expect 106 "A subcommand is required"
expect 106 "output is required" encode "$BUNNY"
expect 109 "not expected: --nope" encode "$BUNNY" x.pomar --nope
expect 105 "not in range 4 to 24" encode "$BUNNY" x.pomar --bits 30
expect 105 "--bits" encode "$BUNNY" x.pomar --bits many
expect 0 "Usage" decode --help

# ---- 2: a value the command cannot use --------------------------------------------------------
expect 2 "unknown mesh file extension '.xyz'" encode in.xyz x.pomar
expect 2 "unknown mesh file extension '.xyz'" decode b.pomar out.xyz
expect 2 "no file extension" encode folder x.pomar
expect 2 "bad memory size 'lots'" encode "$BUNNY" x.pomar --max-memory lots
expect 2 "bad memory size 'lots'" decode b.pomar x.ply --max-memory lots
expect 2 "bad --drop 'bogus'" encode "$BUNNY" x.pomar --drop bogus
expect 2 "bad --drop 'bogus'" verify "$BUNNY" b.pomar --drop bogus
expect 2 "level 9999 does not exist" decode p.pomar x.ply --level 9999
expect 2 "level 9999 does not exist" decode b.pomar x.ply --level 9999
expect 2 "cluster 99999 does not exist" decode b.pomar x.ply --cluster 99999
expect 2 "must be a non-negative integer" decode b.pomar x.ply --cluster -1
expect 2 "the level after ':' must be an integer" decode b.pomar x.ply --cluster 1:x
expect 2 "expected 4 numbers" decode b.pomar x.ply --sphere 1,2
expect 2 "'a' is not a number" decode b.pomar x.ply --sphere a,0,0,1
expect 2 "expected 6 numbers" decode b.pomar x.ply --box 1,2,3
expect 2 "no clusters to select" decode p.pomar x.ply --cluster 1
# Refused overwrites: the input as the output, a .pomar under a mesh extension.
cp b.pomar same.pomar
expect 2 "would be overwritten" encode same.pomar same.pomar
expect 2 "would be overwritten" decode same.pomar same.pomar
check "a refused overwrite leaves the input as it was" cmp -s same.pomar b.pomar
expect 2 "--force" encode "$BUNNY" out.ply
check "a refused .pomar under a mesh extension is not written" test ! -e out.ply

# ---- 3: verify mismatch -----------------------------------------------------------------------
"$POMAR" encode "$SAMPLES/many_small_holes.ply" holes.pomar -q || exit 1
expect 3 "MISMATCH" verify "$BUNNY" holes.pomar
"$POMAR" encode textured_sphere.obj no_uv.pomar -q --drop texcoords || exit 1
expect 3 "MISMATCH" verify textured_sphere.obj no_uv.pomar

# ---- 4: damaged or truncated .pomar files -----------------------------------------------------
for cmd in "decode garbage.pomar x.ply" "info garbage.pomar" "verify $BUNNY garbage.pomar"; do
  # shellcheck disable=SC2086
  expect 4 "POMAR signature" $cmd
done
expect 4 "truncated" decode truncated.pomar x.ply
expect 4 "truncated" info truncated.pomar
expect 4 "truncated" decode truncated.pomar x.ply --cluster 0
expect 4 "header checksum" decode header.pomar x.ply
expect 4 "header checksum" info --check header.pomar
expect 4 "level" decode level.pomar x.ply
expect 4 "level" info --check level.pomar
expect 4 "cluster" decode cluster.pomar x.ply
expect 4 "cluster" info --check cluster.pomar
expect 4 "cluster" verify "$BUNNY" cluster.pomar
rm -f skipped.ply
expect 4 "skipped" decode cluster.pomar skipped.ply --skip-damaged
check "decode --skip-damaged writes its output (exit 4)" test -s skipped.ply
for s in ATTR MATL TEXI LSLS; do
  expect 4 "checksum mismatch in section '$s'" decode "flip_$s.pomar" x.obj
  expect 4 "checksum mismatch in section '$s'" info --check "flip_$s.pomar"
  expect 4 "checksum mismatch in section '$s'" verify textured_sphere.obj "flip_$s.pomar"
done
for s in ATTR MATL TEXI; do # plain info reads the sections a decode needs first, too
  expect 4 "checksum mismatch in section '$s'" info "flip_$s.pomar"
  expect 4 "$s section is truncated" info "cut_$s.pomar"
done
expect 4 "checksum mismatch in section 'ATTR'" decode flip_ATTR.pomar x.obj --cluster 0
expect 4 "checksum mismatch in section 'ATTR'" decode flip_ATTR.pomar x.obj --skip-damaged
rm -f no_record.obj
expect 4 "LSLS" decode flip_LSLS.pomar no_record.obj --skip-damaged
check "decode --skip-damaged past a damaged LSLS section writes the coded mesh" test -s no_record.obj
for s in ATTR MATL TEXI; do
  expect 4 "$s section is truncated" decode "cut_$s.pomar" x.obj
  expect 4 "$s section is truncated" decode "cut_$s.pomar" x.obj --cluster 0
  expect 4 "$s section is truncated" info --check "cut_$s.pomar"
done
expect 4 "lossless record" decode cut_LSLS.pomar x.obj
expect 4 "lossless record" info --check cut_LSLS.pomar

# ---- 5: a mesh the codec cannot take, a malformed mesh file -----------------------------------
expect 5 "--repair" encode --strict "$SAMPLES/tetra_nonmanifold.off" x.pomar
expect 5 "not a PLY file" encode garbage.ply x.pomar
expect 5 "truncated PLY file" encode truncated.ply x.pomar
expect 5 "references vertex 9" encode bad_index.obj x.pomar
expect 5 "truncated OFF file" encode truncated.off x.pomar
expect 5 "STL" encode short.stl x.pomar
expect 5 "not a PLY file" verify garbage.ply b.pomar
expect 5 "not a PLY file" verify "$BUNNY" b.pomar garbage.ply
expect 5 "normal" encode nan_normal.ply x.pomar

# ---- 6: a file that cannot be read or written -------------------------------------------------
expect 6 "no/such/in.ply" encode no/such/in.ply x.pomar
expect 6 "no/such/in.pomar" decode no/such/in.pomar x.ply
expect 6 "no/such/in.pomar" info no/such/in.pomar
expect 6 "no/such/in.pomar" info --check no/such/in.pomar
expect 6 "no/such/in.ply" verify no/such/in.ply b.pomar
expect 6 "no/such/in.pomar" verify "$BUNNY" no/such/in.pomar
expect 6 "no/such/decoded.ply" verify "$BUNNY" b.pomar no/such/decoded.ply
expect 6 "is a directory" decode folder x.ply
expect 6 "is a directory" info folder
expect 6 "No such file or directory" encode "$BUNNY" no/such/dir/x.pomar
expect 6 "No such file or directory" decode b.pomar no/such/dir/x.ply
expect 6 "Not a directory" encode "$BUNNY" plain_file/x.pomar
expect 6 "Not a directory" decode b.pomar plain_file/x.ply
expect 6 "textured_sphere.png" encode --embed-textures textures_missing/textured_sphere.obj x.pomar
# A write past the file size limit (as a full disk): an I/O error, no temporary file left,
# the previous output untouched.
mkdir limited
echo "previous" >limited/x.pomar
echo "previous" >limited/x.ply
LIMIT_FSIZE=16 # 8 KiB
expect 6 "limited/x.pomar" encode "$BUNNY" limited/x.pomar
expect 6 "limited/x.ply" decode b.pomar limited/x.ply
LIMIT_FSIZE=
check "a write past the size limit leaves no temporary file" \
  test -z "$(find limited -name '.*tmp*' -print -quit)"
check "a write past the size limit leaves the previous outputs" \
  sh -c 'grep -qx previous limited/x.pomar && grep -qx previous limited/x.ply'

# ---- 7: the memory limit ----------------------------------------------------------------------
expect 7 "not enough memory to encode" encode "$BUNNY" x.pomar --max-memory 1M
expect 7 "not enough memory to decode" decode b.pomar x.ply --max-memory 1M
expect 7 "not enough memory to decode" decode b.pomar x.ply --cluster 0 --max-memory 1M

# ---- 8: a .pomar version or section this build does not read ----------------------------------
expect 8 "unsupported .pomar version 9" decode v9.pomar x.obj
expect 8 "unsupported .pomar version 9" info v9.pomar
expect 8 "unsupported .pomar version 9" info --check v9.pomar
expect 8 "'MATX'" decode unknown_section.pomar x.obj
expect 8 "'MATX'" decode unknown_section.pomar x.obj --cluster 0
for s in ATTR MATL TEXI; do
  expect 8 "$s section version 99" decode "v99_$s.pomar" x.obj
  expect 8 "$s section version 99" info --check "v99_$s.pomar"
  expect 8 "$s section version 99" info "v99_$s.pomar"
done

echo "$checks checks, $failures failed"
[ "$failures" -eq 0 ]
