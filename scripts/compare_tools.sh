#!/usr/bin/env bash
# Before/after check for refactors that must not change behaviour: runs two builds of the
# `pomar` tool on the same inputs and compares every output file, message and exit status.
#
#   bash scripts/compare_tools.sh BEFORE_POMAR AFTER_POMAR [POMAR_GEN_MESH]
#
# Inputs (in a temporary folder): samples/*, generated meshes (pomar_gen_mesh: noisy sphere,
# torus, uv sphere; default build/bench/pomar_gen_mesh, skipped if absent), the bunny
# converted by BEFORE to OBJ, OFF, binary and ASCII STL and ASCII PLY. Runs: encode with
# default options, --progressive, --clusters 40 (and --repair on non-manifold samples);
# decode full / --level 4 / --cluster 3 / --sphere and info --json; damaged, truncated and
# garbage files (strict, --skip-damaged, --cluster, info --check); usage, I/O and memory
# errors; a verify mismatch. Exit status 0 when everything is identical.
set -u
BEFORE=${1:?usage: compare_tools.sh BEFORE_POMAR AFTER_POMAR [POMAR_GEN_MESH]}
AFTER=${2:?usage: compare_tools.sh BEFORE_POMAR AFTER_POMAR [POMAR_GEN_MESH]}
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
GEN=${3:-$REPO/build/bench/pomar_gen_mesh}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/in"
cp "$REPO"/samples/*.{ply,obj,off,stl} "$tmp/in/" 2>/dev/null
if [ -x "$GEN" ]; then
  "$GEN" noisy_sphere 20000 "$tmp/in/sphere20k.ply" 7 >/dev/null
  "$GEN" torus 3000 "$tmp/in/torus.ply" >/dev/null
  "$GEN" uv_sphere 2000 "$tmp/in/uv.ply" >/dev/null
fi
"$BEFORE" encode "$REPO/samples/bunny.ply" "$tmp/b.pomar" -q
for out in bunny_dec.obj bunny_dec.off bunny_dec.stl; do "$BEFORE" decode "$tmp/b.pomar" "$tmp/in/$out" -q; done
"$BEFORE" decode "$tmp/b.pomar" "$tmp/in/bunny_asc.stl" --ascii -q
"$BEFORE" decode "$tmp/b.pomar" "$tmp/in/bunny_asc.ply" --ascii -q

fail=0; n=0
run_both() { # NAME EXT ARGS... ; OUT in ARGS is replaced by each tool's output path
  local name=$1 ext=$2; shift 2
  local a=() b=()
  for x in "$@"; do a+=("${x/OUT/$tmp/after.$ext}"); b+=("${x/OUT/$tmp/before.$ext}"); done
  rm -f "$tmp/after.$ext" "$tmp/before.$ext"
  "$BEFORE" "${b[@]}" >"$tmp/before.msg" 2>&1; local rb=$?
  "$AFTER" "${a[@]}" >"$tmp/after.msg" 2>&1; local ra=$?
  n=$((n + 1))
  sed -i "s#$tmp/before#OUT#g" "$tmp/before.msg"; sed -i "s#$tmp/after#OUT#g" "$tmp/after.msg"
  if [ "$rb" != "$ra" ]; then echo "DIFF exit status $name: before $rb after $ra"; fail=1; return; fi
  if ! cmp -s "$tmp/before.msg" "$tmp/after.msg"; then
    echo "DIFF messages $name"; diff "$tmp/before.msg" "$tmp/after.msg" | head -5; fail=1
  fi
  if [ -e "$tmp/before.$ext" ] || [ -e "$tmp/after.$ext" ]; then
    if cmp -s "$tmp/before.$ext" "$tmp/after.$ext"; then
      echo "same  $name (exit $rb, $(stat -c %s "$tmp/after.$ext") bytes)"
    else echo "DIFF output $name"; fail=1; fi
  else echo "same  $name (exit $rb, no output)"; fi
}

for f in "$tmp"/in/*; do
  b=$(basename "$f")
  run_both "encode $b" pomar encode "$f" OUT -q
  run_both "encode $b --progressive" pomar encode "$f" OUT --progressive -q
  run_both "encode $b --clusters 40" pomar encode "$f" OUT --clusters 40 -q
  case $b in *nonmanifold*) run_both "encode $b --repair" pomar encode "$f" OUT --repair -q ;; esac
done
for f in "$REPO/samples/bunny.ply" "$tmp/in/torus.ply"; do
  [ -e "$f" ] || continue
  b=$(basename "$f")
  "$BEFORE" encode "$f" "$tmp/c.pomar" -q; "$BEFORE" encode "$f" "$tmp/p.pomar" --progressive -q
  run_both "decode $b full" ply decode "$tmp/c.pomar" OUT -q
  run_both "decode $b progressive" ply decode "$tmp/p.pomar" OUT -q
  run_both "decode $b progressive --level 4" ply decode "$tmp/p.pomar" OUT --level 4 -q
  run_both "decode $b --level 4" ply decode "$tmp/c.pomar" OUT --level 4 -q
  run_both "decode $b --cluster 3" ply decode "$tmp/c.pomar" OUT --cluster 3 -q
  run_both "decode $b --sphere" ply decode "$tmp/c.pomar" OUT --sphere -0.06,0.16,0.0,0.03 --level 2 -q
  run_both "info $b" txt info "$tmp/c.pomar" --json
done

# Errors: messages and exit statuses must match too.
"$BEFORE" encode "$REPO/samples/bunny.ply" "$tmp/e.pomar" -q --clusters 30
sz=$(stat -c %s "$tmp/e.pomar")
head -c $((sz / 2)) "$tmp/e.pomar" >"$tmp/half.pomar"
head -c 100 "$tmp/e.pomar" >"$tmp/hundred.pomar"
python3 -c 'import random,sys; r=random.Random(1); sys.stdout.buffer.write(bytes(r.randrange(256) for _ in range(4096)))' >"$tmp/garbage.pomar"
python3 - "$tmp/e.pomar" "$tmp/flip_end.pomar" "$tmp/flip_mid.pomar" <<'PY'
import sys
d = bytearray(open(sys.argv[1], "rb").read())
a = bytearray(d); a[len(a) - 40] ^= 0x5A; open(sys.argv[2], "wb").write(a)
b = bytearray(d); b[len(b) // 3] ^= 0x5A; open(sys.argv[3], "wb").write(b)
PY
for f in half hundred garbage flip_end flip_mid; do
  run_both "decode $f.pomar" ply decode "$tmp/$f.pomar" OUT -q
  run_both "decode $f.pomar --skip-damaged" ply decode "$tmp/$f.pomar" OUT -q --skip-damaged
  run_both "decode $f.pomar --cluster 2" ply decode "$tmp/$f.pomar" OUT -q --cluster 2
  run_both "info $f.pomar --check" txt info "$tmp/$f.pomar" --check
done
run_both "decode missing" ply decode "$tmp/nope.pomar" OUT -q
run_both "encode missing" pomar encode "$tmp/nope.ply" OUT -q
run_both "encode unknown ext" pomar encode "$tmp/e.pomar" OUT -q
run_both "decode --level 99" ply decode "$tmp/e.pomar" OUT --level 99 -q
run_both "decode --cluster 99999" ply decode "$tmp/e.pomar" OUT --cluster 99999 -q
run_both "decode --sphere bad" ply decode "$tmp/e.pomar" OUT --sphere 1,2 -q
run_both "encode --max-memory 1M" pomar encode "$REPO/samples/bunny.ply" OUT --max-memory 1M -q
run_both "encode --max-memory bad" pomar encode "$REPO/samples/bunny.ply" OUT --max-memory 5Q -q
run_both "decode --max-memory 1M" ply decode "$tmp/e.pomar" OUT --max-memory 1M -q
[ -e "$tmp/in/torus.ply" ] && run_both "verify mismatch" txt verify "$tmp/in/torus.ply" "$tmp/e.pomar"
if [ $fail = 0 ]; then echo "IDENTICAL: $n runs (outputs, messages, exit statuses)"; else echo "DIFFERENCES FOUND"; fi
exit $fail
