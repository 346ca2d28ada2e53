#!/usr/bin/env bash
# End-to-end tests of the pomar command-line tool.
#
#   bash tests/e2e/cli_test.sh PATH/TO/pomar PATH/TO/samples
#
# Registered in ctest as "cli_end_to_end" (tests/CMakeLists.txt). Each check is an explicit assertion:
# the first failing one prints what failed (with the command's stderr) and exits 1.
# Needs bash, coreutils and python3 (for JSON parsing). About 15 s of CPU; on a loaded
# machine the wall-clock time is several times that, so what bounds a runaway command is
# its CPU time: at most 120 s each (ulimit -t, which load does not stretch; ctest's TIMEOUT
# is a backstop for a command that hangs without using the CPU).
set -euo pipefail
ulimit -t 120

if [ $# -ne 2 ]; then
  echo "usage: $0 POMAR_EXECUTABLE SAMPLES_DIR" >&2
  exit 2
fi
POMAR="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
SAMPLES="$(cd "$2" && pwd)"
BUNNY="$SAMPLES/bunny.ply"
NONMANIFOLD="$SAMPLES/tetra_nonmanifold.off"
[ -x "$POMAR" ] || { echo "FAIL: pomar executable not found: $POMAR" >&2; exit 1; }
[ -f "$BUNNY" ] || { echo "FAIL: sample not found: $BUNNY" >&2; exit 1; }
[ -f "$NONMANIFOLD" ] || { echo "FAIL: sample not found: $NONMANIFOLD" >&2; exit 1; }

WORK="$(mktemp -d "${TMPDIR:-/tmp}/pomar-e2e.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

CHECKS=0
CUR="(setup)"

# ---- helpers -------------------------------------------------------------------------------------

section() { CUR="$*"; printf -- '--- %s\n' "$*"; }

fail() {
  {
    printf 'FAIL [%s]: %s\n' "$CUR" "$*"
    if [ -n "${LAST_CMD:-}" ]; then
      printf '  last command: %s\n' "$LAST_CMD"
      printf '  exit status : %s\n' "$RC"
      printf '  stdout      :\n'; sed 's/^/    /' "$WORK/.out" 2>/dev/null | head -20
      printf '  stderr      :\n'; sed 's/^/    /' "$WORK/.err" 2>/dev/null | head -20
    fi
  } >&2
  exit 1
}

pass() { CHECKS=$((CHECKS + 1)); }

# run CMD...: runs pomar with the arguments; sets RC, OUT, ERR (never aborts the script).
run() {
  LAST_CMD="pomar $*"
  set +e
  "$POMAR" "$@" >"$WORK/.out" 2>"$WORK/.err"
  RC=$?
  set -e
  OUT="$(cat "$WORK/.out")"
  ERR="$(cat "$WORK/.err")"
}

expect_rc() { # expect_rc N
  [ "$RC" -eq "$1" ] || fail "expected exit status $1, got $RC"
  pass
}
expect_nonzero() {
  [ "$RC" -ne 0 ] || fail "expected a non-zero exit status, got 0"
  pass
}
expect_file() { [ -s "$1" ] || fail "expected a non-empty file at $1"; pass; }
expect_no_file() { [ ! -e "$1" ] || fail "expected no file at $1, but it exists"; pass; }
expect_contains() { # expect_contains HAYSTACK NEEDLE WHAT
  case "$1" in
    *"$2"*) pass ;;
    *) fail "$3 does not contain '$2'" ;;
  esac
}
expect_dir_only() { # expect_dir_only DIR [NAME...]: DIR holds exactly these entries (no stray temp files)
  local dir="$1"; shift
  local got want
  got="$(find "$dir" -mindepth 1 -maxdepth 1 -printf '%f\n' | LC_ALL=C sort | tr '\n' ' ')"
  want="$(printf '%s\n' "$@" | LC_ALL=C sort | tr '\n' ' ')"
  [ "$#" -gt 0 ] || want=""
  [ "$got" = "$want" ] || fail "directory $dir holds '$got', expected exactly '$want'"
  pass
}
expect_one_line_error() { # stderr is exactly one line starting with "pomar: error:"
  local n
  n="$(printf '%s\n' "$ERR" | grep -c . || true)"
  [ "$n" -eq 1 ] || fail "expected a one-line error message on stderr, got $n lines"
  case "$ERR" in
    "pomar: error: "*) pass ;;
    *) fail "stderr does not start with 'pomar: error: '" ;;
  esac
}

filesize() { wc -c <"$1" | tr -d ' '; }

# Vertex count announced in a PLY header ("element vertex N"); the header of a binary PLY is ASCII.
ply_vertex_count() {
  LC_ALL=C sed -n -e '/^end_header/q' -e 's/^element vertex \([0-9][0-9]*\).*/\1/p' "$1"
}

# json_get FILE PYTHON_EXPR: evaluates the expression on the parsed object `d`.
json_get() {
  python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
print(eval(sys.argv[2]))' "$1" "$2"
}

# ---- encode / verify / decode ----------------------------------------------------------------------

section "encode bunny.ply"
run encode "$BUNNY" "$WORK/bunny.pomar"
expect_rc 0
expect_file "$WORK/bunny.pomar"
expect_dir_only "$WORK" .err .out bunny.pomar

section "verify bunny.pomar (decode in memory)"
run verify "$BUNNY" "$WORK/bunny.pomar"
expect_rc 0
expect_contains "$OUT" "OK" "stdout of verify"

for ext in ply obj off stl; do
  section "decode to .$ext and verify the decoded file"
  run decode -q "$WORK/bunny.pomar" "$WORK/decoded.$ext"
  expect_rc 0
  expect_file "$WORK/decoded.$ext"
  run verify "$BUNNY" "$WORK/bunny.pomar" "$WORK/decoded.$ext"
  expect_rc 0
  expect_contains "$OUT" "OK" "stdout of verify"
done

section "decode --ascii and verify"
run decode -q --ascii "$WORK/bunny.pomar" "$WORK/decoded_ascii.ply"
expect_rc 0
head -n 2 "$WORK/decoded_ascii.ply" | grep -qx 'format ascii 1.0' || fail "decoded_ascii.ply is not an ASCII PLY"
pass
run verify "$BUNNY" "$WORK/bunny.pomar" "$WORK/decoded_ascii.ply"
expect_rc 0

section "decode --threads 1, 2 and 7 write the same file (full and selective decodes)"
for t in 1 2 7; do
  run decode -q --threads "$t" "$WORK/bunny.pomar" "$WORK/threads$t.ply"
  expect_rc 0
  run decode -q --threads "$t" "$WORK/bunny.pomar" "$WORK/threads_sel$t.ply" --sphere -0.06,0.16,0.0,0.03 --level 12
  expect_rc 0
done
for t in 2 7; do
  cmp -s "$WORK/threads1.ply" "$WORK/threads$t.ply" || fail "decode --threads $t differs from --threads 1"
  pass
  cmp -s "$WORK/threads_sel1.ply" "$WORK/threads_sel$t.ply" || fail "selective decode --threads $t differs from --threads 1"
  pass
done
rm -f "$WORK"/threads*.ply

section "verify reports a mismatch with exit 3"
run decode -q --level 0 "$WORK/bunny.pomar" "$WORK/base.ply"
expect_rc 0
run verify "$BUNNY" "$WORK/bunny.pomar" "$WORK/base.ply"
expect_rc 3

# ---- info --json -------------------------------------------------------------------------------------

section "info --json"
run info --json "$WORK/bunny.pomar"
expect_rc 0
cp "$WORK/.out" "$WORK/info.json"
python3 -c 'import json, sys; json.load(open(sys.argv[1]))' "$WORK/info.json" 2>"$WORK/.err" ||
  fail "info --json output is not valid JSON: $(cat "$WORK/.err")"
pass
for key in vertices faces bits levels connectivity_bits geometry_bits total_bytes; do
  [ "$(json_get "$WORK/info.json" "'$key' in d")" = "True" ] || fail "info --json lacks key '$key'"
  pass
done
v="$(json_get "$WORK/info.json" "d['vertices']")"
[ "$v" = 34834 ] || fail "info --json: vertices = $v, expected 34834 (35947 minus 1113 unreferenced)"
pass
f="$(json_get "$WORK/info.json" "d['faces']")"
[ "$f" = 69451 ] || fail "info --json: faces = $f, expected 69451"
pass
b="$(json_get "$WORK/info.json" "d['bits']")"
[ "$b" = 12 ] || fail "info --json: bits = $b, expected 12"
pass
tb="$(json_get "$WORK/info.json" "d['total_bytes']")"
[ "$tb" = "$(filesize "$WORK/bunny.pomar")" ] ||
  fail "info --json: total_bytes = $tb, but the file has $(filesize "$WORK/bunny.pomar") bytes"
pass

# ---- --bits ------------------------------------------------------------------------------------------

section "--bits 16 gives a larger file than the default"
run encode -q --bits 16 "$BUNNY" "$WORK/bunny16.pomar"
expect_rc 0
s12="$(filesize "$WORK/bunny.pomar")"
s16="$(filesize "$WORK/bunny16.pomar")"
[ "$s16" -gt "$s12" ] || fail "--bits 16 file ($s16 bytes) is not larger than the default ($s12 bytes)"
pass
[ "$(json_get <("$POMAR" info --json "$WORK/bunny16.pomar") "d['bits']")" = 16 ] ||
  fail "info --json of the --bits 16 file does not say bits = 16"
pass
run verify "$BUNNY" "$WORK/bunny16.pomar"
expect_rc 0

for bad in 3 25; do
  section "--bits $bad is rejected"
  mkdir "$WORK/bits$bad"
  run encode --bits "$bad" "$BUNNY" "$WORK/bits$bad/out.pomar"
  expect_nonzero
  expect_no_file "$WORK/bits$bad/out.pomar"
  expect_dir_only "$WORK/bits$bad"
done

# ---- --level -----------------------------------------------------------------------------------------

for level in 0 5; do
  section "decode --level $level has the vertex count info announces"
  want="$(json_get "$WORK/info.json" "[l['vertices'] for l in d['levels'] if l['level'] == $level][0]")" ||
    fail "info --json has no entry for level $level in 'levels'"
  run decode -q --level "$level" "$WORK/bunny.pomar" "$WORK/level$level.ply"
  expect_rc 0
  got="$(ply_vertex_count "$WORK/level$level.ply")"
  [ -n "$got" ] || fail "no 'element vertex' line in the header of level$level.ply"
  [ "$got" = "$want" ] || fail "level $level: decoded PLY has $got vertices, info --json announces $want"
  pass
done
[ "$(ply_vertex_count "$WORK/level0.ply")" -lt "$(ply_vertex_count "$WORK/level5.ply")" ] ||
  fail "level 5 does not have more vertices than level 0"
pass

section "decode --level 9999 fails and names the level"
mkdir "$WORK/level9999"
run decode --level 9999 "$WORK/bunny.pomar" "$WORK/level9999/out.ply"
expect_rc 2
expect_one_line_error
expect_contains "$ERR" "9999" "stderr"
expect_dir_only "$WORK/level9999"

# ---- non-manifold input ----------------------------------------------------------------------------

section "non-manifold input is encoded by default, one line says what was stored, verify is exact"
mkdir "$WORK/nm"
run encode "$NONMANIFOLD" "$WORK/nm/out.pomar"
expect_rc 0
expect_file "$WORK/nm/out.pomar"
expect_contains "$ERR" "pomar: stored for an exact decode: non-manifold: 2 vertices and 1 edge stored as cuts (" "stderr"
[ "$(printf '%s\n' "$ERR" | grep -c .)" -eq 1 ] || fail "expected exactly one line on stderr, got: $ERR"
pass
expect_contains "$OUT" "lossless record:" "stdout"
run verify "$NONMANIFOLD" "$WORK/nm/out.pomar"
expect_rc 0
expect_contains "$OUT" "the same 6 vertices and 8 oriented triangles" "stdout"
run info "$WORK/nm/out.pomar"
expect_rc 0
expect_contains "$OUT" ".pomar version 5" "stdout"
expect_contains "$OUT" "a full decode gives back the input's 6 vertices and 8 faces exactly" "stdout"
run info --json "$WORK/nm/out.pomar"
expect_rc 0
[ "$(json_get "$WORK/.out" "d['input_vertices']")" = 6 ] || fail "info --json: input_vertices is not 6"
pass
run decode "$WORK/nm/out.pomar" "$WORK/nm/out.off"
expect_rc 0
run verify "$NONMANIFOLD" "$WORK/nm/out.pomar" "$WORK/nm/out.off"
expect_rc 0

section "--strict: non-manifold input is refused without creating the output"
run encode "$NONMANIFOLD" "$WORK/nm/strict.pomar" --strict
expect_rc 5
expect_one_line_error
expect_contains "$ERR" "non-manifold" "stderr"
expect_no_file "$WORK/nm/strict.pomar"

section "--strict: a refused input leaves a pre-existing output file byte-identical"
printf 'precious bytes that must survive a failed encode\n' >"$WORK/nm/existing.pomar"
sum_before="$(sha256sum <"$WORK/nm/existing.pomar")"
run encode "$NONMANIFOLD" "$WORK/nm/existing.pomar" --strict
expect_rc 5
expect_contains "$ERR" "non-manifold" "stderr"
sum_after="$(sha256sum <"$WORK/nm/existing.pomar")"
[ "$sum_before" = "$sum_after" ] || fail "the pre-existing output file was modified by a failed encode"
pass
expect_dir_only "$WORK/nm" existing.pomar out.off out.pomar

section "the --strict refusal hints at the default and at --repair"
run encode "$NONMANIFOLD" "$WORK/nm/hint.pomar" --strict
expect_rc 5
expect_one_line_error
expect_contains "$ERR" "without --strict pomar stores the cut" "stderr"
expect_contains "$ERR" "--repair cuts it for good" "stderr"
expect_no_file "$WORK/nm/hint.pomar"

section "a clean mesh: the same bytes with and without --strict"
run encode "$BUNNY" "$WORK/nm/bunny_strict.pomar" --strict
expect_rc 0
expect_contains "$OUT" "(1113 unreferenced vertices dropped)" "stdout"
run decode "$WORK/nm/bunny_strict.pomar" "$WORK/nm/clean.ply" --ascii
expect_rc 0
run encode "$WORK/nm/clean.ply" "$WORK/nm/clean.pomar"
expect_rc 0
[ -z "$ERR" ] || fail "a clean mesh printed on stderr: $ERR"
pass
run encode "$WORK/nm/clean.ply" "$WORK/nm/clean_strict.pomar" --strict
cmp -s "$WORK/nm/clean.pomar" "$WORK/nm/clean_strict.pomar" || fail "a clean mesh encodes differently with --strict"
pass

section "--keep-order stores the vertex numbering"
run encode "$WORK/nm/clean.ply" "$WORK/nm/bunny_order.pomar" --keep-order
expect_rc 0
expect_contains "$ERR" "the vertex order kept" "stderr"
run verify "$WORK/nm/clean.ply" "$WORK/nm/bunny_order.pomar"
expect_rc 0
run decode "$WORK/nm/bunny_order.pomar" "$WORK/nm/bunny_order.ply" --ascii
expect_rc 0
python3 - "$WORK/nm/clean.ply" "$WORK/nm/bunny_order.ply" <<'PY' || fail "--keep-order: the decoded vertex order differs from the input's"
import sys
def first_vertex_lines(path, n):
    # ASCII PLY files written by pomar: compare the first n vertices.
    with open(path, 'rb') as f:
        data = f.read()
    head, _, body = data.partition(b'end_header\n')
    return [tuple(round(float(x), 2) for x in l.split()[:3]) for l in body.split(b'\n')[:n]]
a, b = first_vertex_lines(sys.argv[1], 200), first_vertex_lines(sys.argv[2], 200)
bad = sum(1 for p, q in zip(a, b) if max(abs(x - y) for x, y in zip(p, q)) > 0.001)
sys.exit(1 if bad else 0)
PY
pass

section "stored errors and the spatial block order by default; --no-stored-errors, --block-order id"
run encode "$WORK/nm/clean.ply" "$WORK/nm/layout_default.pomar"
expect_rc 0
run info "$WORK/nm/layout_default.pomar"
expect_contains "$OUT" "blocks in spatial (Morton) order; stored errors per cluster and level" "pomar info"
expect_contains "$OUT" "section CERR:" "pomar info"
expect_contains "$OUT" "section BLKO:" "pomar info"
run info "$WORK/nm/layout_default.pomar" --json
expect_contains "$OUT" '"stored_errors": true' "pomar info --json"
expect_contains "$OUT" '"block_order": "spatial"' "pomar info --json"
run encode "$WORK/nm/clean.ply" "$WORK/nm/layout_plain.pomar" --no-stored-errors --block-order id
expect_rc 0
run info "$WORK/nm/layout_plain.pomar"
expect_contains "$OUT" "blocks in cluster id order; no stored errors" "pomar info"
case "$OUT" in *"section CERR"*|*"section BLKO"*) fail "--no-stored-errors --block-order id wrote a CERR or BLKO section" ;; esac
pass
[ "$(stat -c %s "$WORK/nm/layout_plain.pomar")" -lt "$(stat -c %s "$WORK/nm/layout_default.pomar")" ] \
  || fail "the file without stored errors is not smaller"
pass
run verify "$WORK/nm/clean.ply" "$WORK/nm/layout_plain.pomar"
expect_rc 0
run verify "$WORK/nm/clean.ply" "$WORK/nm/layout_default.pomar"
expect_rc 0
run encode "$WORK/nm/clean.ply" "$WORK/nm/layout_bad.pomar" --block-order morton
expect_nonzero
expect_no_file "$WORK/nm/layout_bad.pomar"

section "encode --repair cuts the non-manifold input and reports every change"
mkdir "$WORK/repair"
run encode "$NONMANIFOLD" "$WORK/repair/out.pomar" --repair
expect_rc 0
expect_file "$WORK/repair/out.pomar"
expect_contains "$ERR" "pomar: repair: cut 1 edge shared by more than two faces (e.g. edge (1, 0), 4 faces)" "stderr"
expect_contains "$ERR" "pomar: repair: split 2 non-manifold vertices into 4 (e.g. vertex 0 into 2)" "stderr"
[ "$(printf '%s\n' "$ERR" | grep -c '^pomar: repair: ')" -eq 2 ] || fail "expected exactly two repair lines on stderr"
pass
expect_contains "$OUT" "8 vertices, 8 faces" "stdout"
expect_dir_only "$WORK/repair" out.pomar

section "verify --repair accepts the repaired file"
run verify "$NONMANIFOLD" "$WORK/repair/out.pomar" --repair
expect_rc 0
expect_contains "$OUT" "after repair: the same 8 vertices and 8 oriented triangles" "stdout"

section "encode --repair on a manifold mesh changes nothing and says so"
run encode "$BUNNY" "$WORK/repair/bunny.pomar" --repair
expect_rc 0
expect_contains "$ERR" "pomar: repair: nothing to repair" "stderr"
cmp -s "$WORK/repair/bunny.pomar" "$WORK/bunny.pomar" || fail "encode --repair of a manifold mesh differs from a plain encode"
pass

section "a flipped face: stored by default, refused with --strict, repaired, and plain verify of the repaired file points to --repair"
python3 - "$NONMANIFOLD" "$WORK/repair/flipped.off" <<'PY'
import sys
# The first tetrahedron of the sample (vertices 0-3, faces 0-3) with face 1 reversed.
lines = [l for l in open(sys.argv[1]) if l.strip() and not l.startswith("#")]
verts = lines[2:6]
faces = [l.split() for l in lines[8:12]]
faces[1] = [faces[1][0], faces[1][1], faces[1][3], faces[1][2]]
with open(sys.argv[2], "w") as f:
    f.write("OFF\n4 4 0\n" + "".join(verts) + "".join(" ".join(t) + "\n" for t in faces))
PY
run encode "$WORK/repair/flipped.off" "$WORK/repair/flipped.pomar" --strict
expect_rc 5
expect_contains "$ERR" "inconsistently oriented" "stderr"
expect_contains "$ERR" "--repair cuts it for good" "stderr"
run encode "$WORK/repair/flipped.off" "$WORK/repair/flipped_exact.pomar"
expect_rc 0
expect_contains "$ERR" "1 flipped face kept" "stderr"
run verify "$WORK/repair/flipped.off" "$WORK/repair/flipped_exact.pomar"
expect_rc 0
run encode "$WORK/repair/flipped.off" "$WORK/repair/flipped.pomar" --repair --quiet
expect_rc 0
expect_contains "$ERR" "pomar: repair: flipped 1 face to orient the mesh consistently (e.g. face 1)" "stderr"
run verify "$WORK/repair/flipped.off" "$WORK/repair/flipped.pomar"
expect_rc 3
expect_contains "$ERR" "verify with --repair" "stderr"
run verify "$WORK/repair/flipped.off" "$WORK/repair/flipped.pomar" --repair
expect_rc 0

# ---- corrupt .pomar input ---------------------------------------------------------------------------

section "truncated .pomar fails to decode"
mkdir "$WORK/trunc"
half=$(($(filesize "$WORK/bunny.pomar") / 2))
head -c "$half" "$WORK/bunny.pomar" >"$WORK/truncated.pomar"
run decode "$WORK/truncated.pomar" "$WORK/trunc/out.ply"
expect_rc 4
expect_one_line_error
expect_no_file "$WORK/trunc/out.ply"
expect_dir_only "$WORK/trunc"

section "garbage file fails to decode"
mkdir "$WORK/garbage"
# deterministic pseudo-random bytes (no /dev/urandom: keep failures reproducible)
python3 -c 'import random, sys
r = random.Random(1234)
sys.stdout.buffer.write(bytes(r.randrange(256) for _ in range(4096)))' >"$WORK/garbage.pomar"
run decode "$WORK/garbage.pomar" "$WORK/garbage/out.ply"
expect_rc 4
expect_one_line_error
expect_no_file "$WORK/garbage/out.ply"
expect_dir_only "$WORK/garbage"

section "info on a truncated .pomar fails"
run info "$WORK/truncated.pomar"
expect_rc 4
expect_one_line_error

# ---- missing input ---------------------------------------------------------------------------------

section "nonexistent input file"
mkdir "$WORK/missing"
missing="$WORK/no/such/input.ply"
run encode "$missing" "$WORK/missing/out.pomar"
expect_rc 6
expect_one_line_error
expect_contains "$ERR" "$missing" "stderr"
expect_dir_only "$WORK/missing"
run decode "$WORK/no/such/input.pomar" "$WORK/missing/out.ply"
expect_rc 6
expect_one_line_error
expect_contains "$ERR" "$WORK/no/such/input.pomar" "stderr"
expect_dir_only "$WORK/missing"
run info "$WORK/no/such/input.pomar"
expect_rc 6
expect_contains "$ERR" "$WORK/no/such/input.pomar" "stderr"
run verify "$missing" "$WORK/bunny.pomar"
expect_rc 6
expect_contains "$ERR" "$missing" "stderr"

# ---- random access ---------------------------------------------------------------------------------

section "encode with --clusters gives a clustered file"
run encode "$SAMPLES/bunny.ply" "$WORK/ra.pomar" --clusters 500
expect_rc 0
run info "$WORK/ra.pomar" --json
expect_rc 0
printf '%s' "$OUT" >"$WORK/ra.json"
clusters=$(json_get "$WORK/ra.json" 'd["clusters"]')
[ "$clusters" -gt 300 ] && [ "$clusters" -lt 800 ] || fail "expected about 500 clusters, got $clusters"
pass

section "decode one cluster reads part of the file and is a smaller valid mesh"
run decode "$WORK/ra.pomar" "$WORK/one.ply" --cluster 0 --stats
expect_rc 0
expect_contains "$OUT" "bytes read" "--stats output"
expect_contains "$OUT" "clusters refined" "--stats output"
one=$(ply_vertex_count "$WORK/one.ply")
[ "$one" -lt 34834 ] || fail "one cluster decoded $one vertices (full mesh: 34834)"
pass

section "sphere and box requests; every cluster at the finest level is lossless"
run decode "$WORK/ra.pomar" "$WORK/sphere.ply" --sphere -0.06,0.16,0.0,0.02
expect_rc 0
run decode "$WORK/ra.pomar" "$WORK/box.ply" --box -1,-1,-1,0,0.1,1:25
expect_rc 0
run decode "$WORK/ra.pomar" "$WORK/all.ply" --box -1,-1,-1,1,1,1
expect_rc 0
run verify "$SAMPLES/bunny.ply" "$WORK/ra.pomar" "$WORK/all.ply"
expect_rc 0

section "bad selections are clear errors and write nothing"
run decode "$WORK/ra.pomar" "$WORK/bad1.ply" --cluster 999999
expect_rc 2
expect_contains "$ERR" "cluster 999999" "stderr"
expect_no_file "$WORK/bad1.ply"
run decode "$WORK/ra.pomar" "$WORK/bad2.ply" --sphere 1,2,3
expect_rc 2
expect_contains "$ERR" "expected 4 numbers" "stderr"
expect_no_file "$WORK/bad2.ply"
run decode "$WORK/ra.pomar" "$WORK/bad3.ply" --cluster 3:abc
expect_rc 2
expect_no_file "$WORK/bad3.ply"
run encode "$SAMPLES/bunny.ply" "$WORK/prog.pomar" --progressive
expect_rc 0
run decode "$WORK/prog.pomar" "$WORK/bad4.ply" --cluster 0
expect_rc 2
expect_contains "$ERR" "progressive" "stderr"
expect_no_file "$WORK/bad4.ply"

# ---- interrupted writes ---------------------------------------------------------------------------

section "SIGINT while the output is written: old output untouched, no temporary file left"
# The temporary file's name is known in advance (.NAME.tmp.PID.0): made a FIFO, the tool's
# open() of it blocks until a reader comes, so the signal arrives exactly during the write.
mkdir -p "$WORK/sig"
printf 'previous output\n' >"$WORK/sig/out.pomar"
( while [ ! -e "$WORK/sig/go" ]; do sleep 0.01; done
  exec "$POMAR" encode "$BUNNY" "$WORK/sig/out.pomar" -q ) 2>"$WORK/sig/stderr" &
sig_pid=$!
mkfifo "$WORK/sig/.out.pomar.tmp.$sig_pid.0"
touch "$WORK/sig/go"
blocked=0
for _ in $(seq 1 6000); do # up to 60 s (sanitizer builds encode slowly)
  if grep -qE 'partner|fifo' "/proc/$sig_pid/wchan" 2>/dev/null; then blocked=1; break; fi
  kill -0 "$sig_pid" 2>/dev/null || break
  sleep 0.01
done
if [ "$blocked" = 1 ]; then
  kill -INT "$sig_pid"
  set +e; wait "$sig_pid"; sig_rc=$?; set -e
  [ "$sig_rc" -eq 130 ] || fail "interrupted encode: expected death by SIGINT (130), got $sig_rc"; pass
  [ ! -e "$WORK/sig/.out.pomar.tmp.$sig_pid.0" ] || fail "the temporary file is still there"; pass
  [ "$(cat "$WORK/sig/out.pomar")" = "previous output" ] || fail "the previous output changed"; pass
else
  # /proc/PID/wchan unreadable here: cannot tell when the tool blocks; say so and go on.
  kill "$sig_pid" 2>/dev/null || true
  wait "$sig_pid" 2>/dev/null || true
  echo "  (skipped: /proc/PID/wchan does not show the blocked open on this system)"
fi
rm -rf "$WORK/sig"

# ---- damaged and truncated files -------------------------------------------------------------------

section "damaged cluster block: strict decode fails, --skip-damaged decodes the rest"
run encode "$SAMPLES/bunny.ply" "$WORK/ok.pomar" -q
expect_rc 0
run info "$WORK/ok.pomar" --check
expect_rc 0
expect_contains "$OUT" "every block passes" "stdout of info --check"
# Flip one byte in the middle of the cluster data (after the global part).
"$POMAR" info "$WORK/ok.pomar" --json >"$WORK/ok.json"
python3 - "$WORK/ok.pomar" "$WORK/damaged.pomar" "$WORK/truncated.pomar" "$(json_get "$WORK/ok.json" "d['global_bytes']")" <<'PY'
import sys
src, dmg, trunc, global_bytes = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
data = bytearray(open(src, "rb").read())
at = global_bytes + (len(data) - global_bytes) // 3
data[at] ^= 0x5A
open(dmg, "wb").write(data)
open(trunc, "wb").write(open(src, "rb").read()[: global_bytes + (len(data) - global_bytes) * 3 // 4])
PY
run decode "$WORK/damaged.pomar" "$WORK/strict.ply"
expect_rc 4
expect_one_line_error
expect_contains "$ERR" "cluster" "stderr"
expect_contains "$ERR" "--skip-damaged" "stderr (hint)"
expect_no_file "$WORK/strict.ply"
run info "$WORK/damaged.pomar" --check
expect_rc 4
expect_contains "$OUT" "1 damaged block" "stdout of info --check"
run decode "$WORK/damaged.pomar" "$WORK/skipped.ply" --skip-damaged
expect_rc 4
expect_file "$WORK/skipped.ply"
expect_contains "$ERR" "damaged block skipped" "stderr"
expect_contains "$ERR" "kept at level" "stderr"
[ "$(ply_vertex_count "$WORK/skipped.ply")" -gt 0 ] || fail "no vertices in the mesh decoded around the damage"; pass
# The result is a valid manifold mesh: it re-encodes.
run encode "$WORK/skipped.ply" "$WORK/skipped.pomar" -q
expect_rc 0
run decode "$WORK/damaged.pomar" "$WORK/region.ply" --sphere -0.06,0.16,0.0,0.03 --skip-damaged
[ "$RC" -eq 0 ] || [ "$RC" -eq 4 ] || fail "region decode with --skip-damaged: exit $RC"; pass
expect_file "$WORK/region.ply"

section "truncated file: --skip-damaged decodes the blocks that arrived"
run decode "$WORK/truncated.pomar" "$WORK/t_strict.ply"
expect_rc 4
expect_contains "$ERR" "truncated" "stderr"
expect_no_file "$WORK/t_strict.ply"
run decode "$WORK/truncated.pomar" "$WORK/t_skip.ply" --skip-damaged
expect_rc 4
expect_file "$WORK/t_skip.ply"
expect_contains "$ERR" "truncated .pomar file: the block of cluster" "stderr"
run info "$WORK/truncated.pomar" --check
expect_rc 4
expect_contains "$OUT" "truncated file" "stdout of info --check"

# ---- memory limits (--max-memory) -----------------------------------------------------------------------

section "encode --max-memory 1M: refused from the header, no output"
mkdir -p "$WORK/mem"
run encode "$SAMPLES/bunny.ply" "$WORK/mem/out.pomar" --max-memory 1M
expect_rc 7
expect_one_line_error
expect_contains "$ERR" "not enough memory to encode 35,947 vertices and 69,451 faces" "stderr"
expect_contains "$ERR" "the limit is 1.0 MiB; set the limit with pomar --max-memory" "stderr"
expect_dir_only "$WORK/mem"

section "encode --max-memory: sizes that fit, 'none', bad sizes"
for size in 1.5GiB 2G 512M none 4294967296; do
  run encode "$SAMPLES/bunny.ply" "$WORK/mem/ok.pomar" --max-memory "$size" -q
  expect_rc 0
  expect_file "$WORK/mem/ok.pomar"
  rm -f "$WORK/mem/ok.pomar"
done
for size in 12x "" 1.5.2G 5Q; do
  run encode "$SAMPLES/bunny.ply" "$WORK/mem/bad.pomar" --max-memory "$size"
  expect_rc 2
  expect_contains "$ERR" "bad memory size" "stderr"
  expect_no_file "$WORK/mem/bad.pomar"
done

section "decode --max-memory 1M: refused from the header, no output"
run encode "$SAMPLES/bunny.ply" "$WORK/mem/bunny.pomar" -q
expect_rc 0
for mode in full selective; do
  extra=(); [ "$mode" = selective ] && extra=(--cluster 0)
  run decode "$WORK/mem/bunny.pomar" "$WORK/mem/out.ply" --max-memory 1M "${extra[@]}"
  expect_rc 7
  expect_one_line_error
  expect_contains "$ERR" "not enough memory to decode" "stderr"
  expect_no_file "$WORK/mem/out.ply"
done
run decode "$WORK/mem/bunny.pomar" "$WORK/mem/out.ply" --max-memory 64M -q
expect_rc 0
expect_file "$WORK/mem/out.ply"
rm -f "$WORK/mem/out.ply"

section "decode --max-memory below a whole decode: written region by region, the same file"
# The bunny without its unreferenced vertices (--strict: no lossless record). A whole decode
# needs about 12.2 MiB on one thread; 12M holds a few regions at a time.
run encode --strict "$SAMPLES/bunny.ply" "$WORK/mem/strict.pomar" -q
expect_rc 0
run decode "$WORK/mem/strict.pomar" "$WORK/mem/whole.ply" -q
expect_rc 0
run decode "$WORK/mem/strict.pomar" "$WORK/mem/regions.ply" --max-memory 12M --threads 1
expect_rc 0
expect_contains "$OUT" "34834 vertices, 69451 faces (decoded in" "stdout"
expect_contains "$OUT" "regions within 12.0 MiB" "stdout"
cmp -s "$WORK/mem/whole.ply" "$WORK/mem/regions.ply" || fail "the region-by-region PLY differs from the whole decode's"
pass
run decode "$WORK/mem/strict.pomar" "$WORK/mem/regions.obj" --max-memory 12M --threads 1
expect_rc 7
expect_one_line_error
expect_contains "$ERR" "(to a binary .ply, a full decode is written region by region within the limit)" "stderr"
expect_no_file "$WORK/mem/regions.obj"
run decode "$WORK/mem/strict.pomar" "$WORK/mem/small.ply" --max-memory 9M --threads 1
expect_rc 7
expect_one_line_error
expect_contains "$ERR" "in bounded memory: its smallest region" "stderr"
expect_contains "$ERR" "the limit is 9.0 MiB" "stderr"
expect_no_file "$WORK/mem/small.ply"
run decode "$WORK/mem/bunny.pomar" "$WORK/mem/small.ply" --max-memory 14M --threads 1
expect_rc 7
expect_one_line_error
expect_contains "$ERR" "cannot be decoded in bounded memory: it carries a lossless record" "stderr"
expect_no_file "$WORK/mem/small.ply"
expect_dir_only "$WORK/mem" bunny.pomar strict.pomar whole.ply regions.ply

section "decode --sphere/--cluster --max-memory: the region asked for is checked too"
# 16M holds the base clustered mesh (14.0 MiB on two threads) and one cluster's
# neighbourhood, not the whole mesh at full resolution (21.5 MiB).
run decode "$WORK/mem/bunny.pomar" "$WORK/mem/out.ply" --sphere 0,0,0,10 --max-memory 16M --threads 2
expect_rc 7
expect_one_line_error
expect_contains "$ERR" "not enough memory to refine the clusters asked for to about 34,834 vertices" "stderr"
expect_no_file "$WORK/mem/out.ply"
run decode "$WORK/mem/bunny.pomar" "$WORK/mem/out.ply" --cluster 0 --max-memory 16M --threads 2 -q
expect_rc 0
expect_file "$WORK/mem/out.ply"

section "a PLY header claiming 2^31 (or 2^31 - 1) vertices with a tiny body"
for count in 2147483648 2147483647; do
  printf 'ply\nformat binary_little_endian 1.0\nelement vertex %s\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n' "$count" >"$WORK/mem/huge.ply"
  printf '\0\0\0\0\0\0\0\0\0\0\0\0' >>"$WORK/mem/huge.ply"
  for limit in none 1G; do
    run encode "$WORK/mem/huge.ply" "$WORK/mem/huge.pomar" --max-memory "$limit"
    expect_rc "$([ "$count" = 2147483647 ] && [ "$limit" = 1G ] && echo 7 || echo 5)" # memory limit, else invalid mesh file
    expect_one_line_error
    if [ "$count" = 2147483648 ]; then
      expect_contains "$ERR" "invalid PLY header: bad element line" "stderr"
    elif [ "$limit" = none ]; then
      expect_contains "$ERR" "truncated PLY file (vertex 0 of 2147483647)" "stderr"
    else
      expect_contains "$ERR" "not enough memory to encode 2,147,483,647 vertices and 1 faces" "stderr"
    fi
    expect_no_file "$WORK/mem/huge.pomar"
  done
done

# ---- per-vertex attributes ---------------------------------------------------------------------------

section "attributes: a coloured, scalar-carrying PLY (generated: the bunny with colour, normals, quality)"
mkdir -p "$WORK/attr"
python3 - "$BUNNY" "$WORK/attr/c.ply" "$WORK/attr/nan.ply" <<'PY'
import math, struct, sys
data = open(sys.argv[1], 'rb').read()
end = data.index(b'end_header\n') + len(b'end_header\n')
head = data[:end].decode()
nv = int(head.split('element vertex ')[1].split()[0])
nf = int(head.split('element face ')[1].split()[0])
pos = struct.unpack_from('<%df' % (3 * nv), data, end)
faces = data[end + 12 * nv:]
def write(path, nan):
    out = ['ply', 'format binary_little_endian 1.0', 'comment TextureFile skin.png',
           'element vertex %d' % nv] + ['property float %s' % a for a in 'xyz'] + \
          ['property uchar red', 'property uchar green', 'property uchar blue',
           'property float nx', 'property float ny', 'property float nz', 'property float quality',
           'element face %d' % nf, 'property list uchar int vertex_indices', 'end_header']
    body = bytearray()
    for v in range(nv):
        x, y, z = pos[3 * v:3 * v + 3]
        r = math.sqrt(x * x + y * y + z * z) or 1.0
        q = float('nan') if nan and v == 7 else 100 * x * y
        body += struct.pack('<3f3B4f', x, y, z, int(128 + 120 * math.sin(40 * x)),
                            int(128 + 120 * math.sin(40 * y)), v % 256, x / r, y / r, z / r, q)
    open(path, 'wb').write(('\n'.join(out) + '\n').encode() + bytes(body) + faces)
write(sys.argv[2], False)
write(sys.argv[3], True)
PY
run encode "$WORK/attr/c.ply" "$WORK/attr/c.pomar"
expect_rc 0
expect_contains "$OUT" "attribute colour" "encode output"
expect_contains "$OUT" "attribute normal" "encode output"
expect_contains "$OUT" "attribute quality" "encode output"
run info --json "$WORK/attr/c.pomar"
expect_rc 0
printf '%s' "$OUT" >"$WORK/attr/info.json"
[ "$(json_get "$WORK/attr/info.json" "d['version']")" = 5 ] || fail "an attribute file is version 5"; pass
[ "$(json_get "$WORK/attr/info.json" "len(d['attributes'])")" = 3 ] || fail "3 attributes"; pass
[ "$(json_get "$WORK/attr/info.json" "[a['kind'] for a in d['attributes']]")" = "['colour', 'normal', 'scalar']" ] ||
  fail "attribute kinds in info --json"; pass
[ "$(json_get "$WORK/attr/info.json" "d['attributes'][0]['exact']")" = True ] || fail "colour is exact"; pass
[ "$(json_get "$WORK/attr/info.json" "d['texture_files']")" = "['skin.png']" ] || fail "texture file kept"; pass
run info "$WORK/attr/c.pomar"
expect_contains "$OUT" "bits/vertex (RGB, 8 bits exact)" "info text"
run verify "$WORK/attr/c.ply" "$WORK/attr/c.pomar"
expect_rc 0
expect_contains "$OUT" "colour 'colour': RGB, 8 bits exact, max error 0" "verify"
expect_contains "$OUT" "normal 'normal': 9-bit octahedral" "verify"

section "attributes: decode writes them, --no-attributes leaves them out, verify reads a decoded file"
run decode "$WORK/attr/c.pomar" "$WORK/attr/back.ply"
expect_rc 0
run verify "$WORK/attr/c.ply" "$WORK/attr/c.pomar" "$WORK/attr/back.ply"
expect_rc 0
run decode --no-attributes "$WORK/attr/c.pomar" "$WORK/attr/plain.ply"
expect_rc 0
grep -q "property uchar red" "$WORK/attr/plain.ply" && fail "--no-attributes wrote colours"; pass
run verify "$WORK/attr/c.ply" "$WORK/attr/c.pomar" "$WORK/attr/plain.ply"
expect_rc 3
expect_contains "$ERR" "missing from the decoded mesh" "verify of a mesh without attributes"
run decode --level 3 "$WORK/attr/c.pomar" "$WORK/attr/l3.ply"
expect_rc 0
grep -q "property uchar red" "$WORK/attr/l3.ply" || fail "an intermediate level has colours"; pass
run decode "$WORK/attr/c.pomar" "$WORK/attr/back.stl"
expect_rc 0
expect_contains "$ERR" "back.stl cannot hold colours, normals, scalars 'quality', texture file names: not written" "STL warning"
[ "$(printf '%s\n' "$ERR" | grep -c warning)" = 1 ] || fail "one warning line for STL"; pass
run decode "$WORK/attr/c.pomar" "$WORK/attr/back.off"
expect_rc 0
expect_contains "$ERR" "back.off cannot hold scalars 'quality', texture file names: not written" "OFF warning"
head -1 "$WORK/attr/back.off" | grep -qx "CNOFF" || fail "OFF with colour and normals is CNOFF"; pass
run decode --no-attributes "$WORK/attr/c.pomar" "$WORK/attr/plain.stl"
expect_rc 0
[ -z "$ERR" ] || fail "no warning when there is nothing to drop"; pass

section "attributes: --drop, --exact-attributes, NaN in quantized mode"
run encode --drop colour,normals "$WORK/attr/c.ply" "$WORK/attr/d.pomar"
expect_rc 0
run verify "$WORK/attr/c.ply" "$WORK/attr/d.pomar"
expect_rc 3
expect_contains "$ERR" "not in the file" "verify without --drop"
run verify --drop colour,normals "$WORK/attr/c.ply" "$WORK/attr/d.pomar"
expect_rc 0
run encode --drop colours,bogus "$WORK/attr/c.ply" "$WORK/attr/x.pomar"
expect_rc 2
expect_contains "$ERR" "'bogus' is not one of colour, normals, scalars, texcoords, all" "bad --drop"
run encode "$WORK/attr/nan.ply" "$WORK/attr/nan.pomar"
expect_rc 5
expect_contains "$ERR" "scalar attribute 'quality' of vertex 7 is NaN" "NaN in quantized mode"
expect_no_file "$WORK/attr/nan.pomar"
run encode --exact-attributes "$WORK/attr/nan.ply" "$WORK/attr/nan.pomar"
expect_rc 0
run verify "$WORK/attr/nan.ply" "$WORK/attr/nan.pomar"
expect_rc 0
expect_contains "$OUT" "exact floats, max error 0" "exact mode"
run encode --normal-bits 12 --scalar-bits 8 "$WORK/attr/c.ply" "$WORK/attr/b.pomar"
expect_rc 0
run verify "$WORK/attr/c.ply" "$WORK/attr/b.pomar"
expect_rc 0
expect_contains "$OUT" "12-bit octahedral" "--normal-bits"

section "attributes: RGBA with every alpha 255 and zero-length normals, both layouts, every level"
python3 - "$BUNNY" "$WORK/attr/rgba.ply" "$WORK/attr/zero.obj" "$WORK/attr/nann.ply" <<'PY'
import math, struct, sys
data = open(sys.argv[1], 'rb').read()
end = data.index(b'end_header\n') + len(b'end_header\n')
head = data[:end].decode()
nv = int(head.split('element vertex ')[1].split()[0])
nf = int(head.split('element face ')[1].split()[0])
pos = struct.unpack_from('<%df' % (3 * nv), data, end)
faces = data[end + 12 * nv:]
out = ['ply', 'format binary_little_endian 1.0', 'element vertex %d' % nv] + \
      ['property float %s' % a for a in 'xyz'] + \
      ['property uchar %s' % c for c in ('red', 'green', 'blue', 'alpha')] + \
      ['element face %d' % nf, 'property list uchar int vertex_indices', 'end_header']
body = bytearray()
for v in range(nv):
    body += struct.pack('<3f4B', *pos[3 * v:3 * v + 3], v % 256, (7 * v) % 256, 40, 255)
open(sys.argv[2], 'wb').write(('\n'.join(out) + '\n').encode() + bytes(body) + faces)
out = out[:3] + ['property float %s' % a for a in 'xyz'] + \
      ['property float %s' % a for a in ('nx', 'ny', 'nz')] + out[-3:]
body = bytearray()
for v in range(nv):  # normals of length 0 are fine, a NaN (vertex 5) is not
    body += struct.pack('<6f', *pos[3 * v:3 * v + 3], 0, float('nan') if v == 5 else 0, 0)
open(sys.argv[4], 'wb').write(('\n'.join(out) + '\n').encode() + bytes(body) + faces)
tris = [struct.unpack_from('<3i', faces, 13 * f + 1) for f in range(nf)]
used = sorted(set(v for t in tris for v in t)) # (OBJ: a vertex no face uses has no normal)
index = {v: i + 1 for i, v in enumerate(used)}
def obj(path):
    lines = []
    for v in used:
        x, y, z = pos[3 * v:3 * v + 3]
        lines.append('v %r %r %r' % (x, y, z))
    for v in used:
        x, y, z = pos[3 * v:3 * v + 3]
        r = math.sqrt(x * x + y * y + z * z) or 1.0
        if v % 50 == 3:
            lines.append('vn 0 0 0')
        else:
            lines.append('vn %r %r %r' % (x / r, y / r, z / r))
    for t in tris:
        a, b, c = (index[v] for v in t)
        lines.append('f %d//%d %d//%d %d//%d' % (a, a, b, b, c, c))
    open(path, 'w').write('\n'.join(lines) + '\n')
obj(sys.argv[3])
PY
for layout in --progressive --cluster-ratio=0.02; do
  run encode "$layout" "$WORK/attr/rgba.ply" "$WORK/attr/rgba.pomar"
  expect_rc 0
  expect_contains "$OUT" "(RGBA, 8 bits exact)" "encode output of an RGBA PLY ($layout)"
  run verify "$WORK/attr/rgba.ply" "$WORK/attr/rgba.pomar"
  expect_rc 0
  expect_contains "$OUT" "colour 'colour': RGBA, 8 bits exact, max error 0" "verify ($layout)"
  for level in 0 2 -1; do
    if [ "$level" = -1 ]; then run decode "$WORK/attr/rgba.pomar" "$WORK/attr/rgba_back.ply"
    else run decode --level "$level" "$WORK/attr/rgba.pomar" "$WORK/attr/rgba_back.ply"; fi
    expect_rc 0
    grep -aq "^property uchar alpha$" "$WORK/attr/rgba_back.ply" || fail "level $level ($layout) lost the alpha"; pass
  done
  run encode "$layout" "$WORK/attr/zero.obj" "$WORK/attr/zero.pomar"
  expect_rc 0
  expect_contains "$OUT" "attribute normal" "encode output of an OBJ with zero normals ($layout)"
  run verify "$WORK/attr/zero.obj" "$WORK/attr/zero.pomar"
  expect_rc 0
  expect_contains "$OUT" "normal 'normal': 9-bit octahedral" "verify of zero normals ($layout)"
  for level in 1 -1; do
    if [ "$level" = -1 ]; then run decode --ascii "$WORK/attr/zero.pomar" "$WORK/attr/zero_back.ply"
    else run decode --ascii --level "$level" "$WORK/attr/zero.pomar" "$WORK/attr/zero_back.ply"; fi
    expect_rc 0
    grep -q "^property float nx$" "$WORK/attr/zero_back.ply" || fail "level $level ($layout) lost the normals"; pass
  done
  # The full decode has as many normals of exactly 0 0 0 as the input.
  python3 - "$WORK/attr/zero.obj" "$WORK/attr/zero_back.ply" <<'PY' || fail "zero normals not kept exactly ($layout)"
import sys
want = sum(1 for l in open(sys.argv[1]) if l.strip() == 'vn 0 0 0')
text = open(sys.argv[2]).read().split('end_header\n')[1].splitlines()
nv = int(open(sys.argv[2]).read().split('element vertex ')[1].split()[0])
got = sum(1 for l in text[:nv] if l.split()[3:6] == ['0', '0', '0'])
sys.exit(0 if want > 0 and got == want else 1)
PY
  pass
done
run encode "$WORK/attr/nann.ply" "$WORK/attr/nann.pomar"
expect_rc 5
expect_contains "$ERR" "normal attribute 'normal' of vertex 5 is NaN" "a NaN normal is an error naming the vertex"
expect_no_file "$WORK/attr/nann.pomar"

# ---- --help ------------------------------------------------------------------------------------------

section "--help"
run --help
expect_rc 0
for sub in encode decode info verify; do expect_contains "$OUT" "$sub" "pomar --help"; done

section "a textured OBJ with --embed-textures: one self-contained file; decode writes the image beside its output"
TEX="$WORK/tex"
mkdir -p "$TEX/in" "$TEX/out" "$TEX/again"
cp "$SAMPLES/textured_sphere.obj" "$SAMPLES/textured_sphere.mtl" "$SAMPLES/textured_sphere.png" "$TEX/in/"
run encode --embed-textures "$TEX/in/textured_sphere.obj" "$TEX/sphere.pomar"
expect_rc 0
expect_contains "$ERR" "texture seam edges" "encode's stderr"
run info "$TEX/sphere.pomar"
expect_rc 0
expect_contains "$OUT" "texture file textured_sphere.png (embedded, " "pomar info"
expect_contains "$OUT" "per-corner texture coordinates" "pomar info"
run verify "$TEX/in/textured_sphere.obj" "$TEX/sphere.pomar"
expect_rc 0
run decode -q "$TEX/sphere.pomar" "$TEX/out/back.obj"
expect_rc 0
cmp -s "$TEX/out/textured_sphere.png" "$SAMPLES/textured_sphere.png" || fail "the embedded image did not come back bit for bit"
pass
run verify "$TEX/in/textured_sphere.obj" "$TEX/sphere.pomar" "$TEX/out/back.obj"
expect_rc 0
# An existing file of that name is never replaced.
printf 'not an image' >"$TEX/again/textured_sphere.png"
run decode "$TEX/sphere.pomar" "$TEX/again/back.obj"
expect_rc 0
expect_contains "$ERR" "exists and differs from the embedded texture" "decode's stderr"
[ "$(cat "$TEX/again/textured_sphere.png")" = "not an image" ] || fail "decode replaced an existing file"
pass
# A texture file that is not there is named.
rm "$TEX/in/textured_sphere.png"
run encode --embed-textures "$TEX/in/textured_sphere.obj" "$TEX/missing.pomar"
expect_nonzero
expect_contains "$ERR" "texture file 'textured_sphere.png'" "encode's error"
expect_no_file "$TEX/missing.pomar"

section "no command overwrites its input; a .pomar under a mesh extension needs --force"
mkdir -p "$WORK/guard"
cp "$BUNNY" "$WORK/guard/b.ply"
ln -sf b.ply "$WORK/guard/link.ply"
before="$(cksum <"$WORK/guard/b.ply")"
run encode "$WORK/guard/b.ply" "$WORK/guard/b.ply"
expect_rc 2
expect_contains "$ERR" "is the input" "encode's error"
run encode --force "$WORK/guard/b.ply" "$WORK/guard/b.ply"
expect_rc 2
expect_contains "$ERR" "is the input" "encode's error"
run encode --force "$WORK/guard/b.ply" "$WORK/guard/link.ply"
expect_rc 2
expect_contains "$ERR" "is the input" "encode's error"
[ "$(cksum <"$WORK/guard/b.ply")" = "$before" ] || fail "the input was changed"
pass
run encode "$WORK/guard/b.ply" "$WORK/guard/out.ply"
expect_rc 2
expect_contains "$ERR" "mesh file's extension" "encode's error"
expect_no_file "$WORK/guard/out.ply"
run encode --force -q "$WORK/guard/b.ply" "$WORK/guard/out.ply"
expect_rc 0
expect_file "$WORK/guard/out.ply"
run encode -q "$WORK/guard/b.ply" "$WORK/guard/b.pomar"
expect_rc 0
run decode "$WORK/guard/b.pomar" "$WORK/guard/b.pomar"
expect_nonzero
run decode "$WORK/guard/b.ply" "$WORK/guard/back.ply"
expect_nonzero
expect_contains "$ERR" "b.ply: not a valid .pomar file" "decode's error naming the file"

section "an output that is a pipe or a device is written in place, not replaced by a file"
mkfifo "$WORK/guard/out.pomar.fifo"
cat "$WORK/guard/out.pomar.fifo" >"$WORK/guard/from_fifo.pomar" &
reader=$!
run encode -q "$WORK/guard/b.ply" "$WORK/guard/out.pomar.fifo"
wait "$reader"
expect_rc 0
[ -p "$WORK/guard/out.pomar.fifo" ] || fail "the FIFO was replaced by a regular file"
pass
cmp -s "$WORK/guard/from_fifo.pomar" "$WORK/guard/b.pomar" || fail "what came through the FIFO differs from the file encode writes"
pass
run encode -q "$WORK/guard/b.ply" /dev/null
expect_rc 0
[ -c /dev/null ] || fail "/dev/null is no longer a character device"
pass
mkdir -p "$WORK/guard/dir.ply"
run decode -q "$WORK/guard/b.pomar" "$WORK/guard/dir.ply"
expect_nonzero
expect_contains "$ERR" "is a directory" "decode's error for a directory output"

help_mentions() { # help_mentions SUBCOMMAND OPTION...
  local sub="$1"; shift
  section "$sub --help"
  run "$sub" --help
  expect_rc 0
  local opt
  for opt in "$@"; do expect_contains "$OUT" "$opt" "pomar $sub --help"; done
}
help_mentions encode --bits --progressive --clusters --cluster-ratio --repair --strict --keep-order --quiet --max-memory 512M input output \
  --no-stored-errors --block-order spatial --drop --normal-bits --scalar-bits --texcoord-bits --exact-attributes --embed-textures --force
help_mentions decode --level --cluster --sphere --box --stats --ascii --quiet --skip-damaged --max-memory input output \
  --no-attributes
help_mentions info --json --check input
help_mentions verify original pomar decoded --repair --drop

LAST_CMD=""
printf 'cli_end_to_end: all %d checks passed\n' "$CHECKS"
