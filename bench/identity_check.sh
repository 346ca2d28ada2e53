#!/usr/bin/env bash
# Byte identity of a build against a reference `pomar` tool: the .pomar files the two
# encoders write and the meshes the two decoders write are compared with `cmp`.
#
#   bash bench/identity_check.sh REF_POMAR NEW_POMAR [--quick]
#
# Meshes: samples/*.ply, what of /work/shared/data (or $POMAR_DATA) is present (bunny,
# horse with normals, armadillo colour, fertility, many_small_holes with colour, dragon),
# generated noisy spheres of 20k, 134k and 1M vertices (--quick: 20k and 134k, no dragon).
# Encodes: default, --progressive, --threads 1/2/7. Decodes (of the reference's file):
# full with --threads 1/2/7, --level, --cluster, --sphere, --no-attributes, OBJ output.
# Prints one line per difference and a summary; exit status 1 if anything differs.
set -u
REF=${1:?reference pomar tool}
NEW=${2:?pomar tool to check}
QUICK=${3:-}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
DATA=${POMAR_DATA:-/work/shared/data}
GEN=$ROOT/build/bench/pomar_gen_mesh
W=$(mktemp -d /tmp/identity.XXXXXX)
trap 'rm -rf "$W"' EXIT
fail=0
pairs=0

same() { # label file_a file_b
  pairs=$((pairs + 1))
  if ! cmp -s "$2" "$3"; then
    echo "DIFFERENT: $1"
    fail=1
  fi
}

run_both() { # label out_ext args... (the output path is the last arg, written as OUT)
  local label=$1 ext=$2
  shift 2
  local a=$W/ref.$ext b=$W/new.$ext
  rm -f "$a" "$b"
  "$REF" "${@/#OUT/$a}" >/dev/null 2>"$W/ref.err"
  local ra=$?
  "$NEW" "${@/#OUT/$b}" >/dev/null 2>"$W/new.err"
  local rb=$?
  if [ $ra -ne $rb ]; then
    echo "DIFFERENT: $label: exit status $ra vs $rb"
    fail=1
    return
  fi
  [ -f "$a" ] || [ -f "$b" ] || return 0
  same "$label" "$a" "$b"
}

# shellcheck source=bench/identity_meshes.sh
. "$ROOT/bench/identity_meshes.sh"
identity_meshes "$W" bunny.ply horse.ply armadillo_50k.obj fertility_23k.off \
  meshlab_many_small_holes.ply

for m in "${meshes[@]}"; do
  name=$(basename "$m")
  for opts in "" "--progressive" "--threads 1" "--threads 2" "--threads 7"; do
    # shellcheck disable=SC2086
    run_both "$name encode $opts" pomar encode $opts "$m" OUT
  done
  "$REF" encode "$m" "$W/$name.pomar" >/dev/null 2>&1 || continue
  "$REF" encode --progressive "$m" "$W/$name.p.pomar" >/dev/null 2>&1
  for opts in "" "--threads 1" "--threads 2" "--threads 7" "--level 2" "--no-attributes" \
    "--cluster 0 --cluster 3:4" "--level 1 --cluster 1" "--box 0,-1e9,-1e9,1e9,1e9,1e9" "--sphere 0,0,0,1e9:25"; do
    # shellcheck disable=SC2086
    run_both "$name decode $opts" ply decode $opts "$W/$name.pomar" OUT
  done
  run_both "$name decode (OBJ)" obj decode "$W/$name.pomar" OUT
  run_both "$name decode progressive file" ply decode "$W/$name.p.pomar" OUT
  run_both "$name decode progressive file --level 3" ply decode --level 3 "$W/$name.p.pomar" OUT
done
echo "identity: $pairs pairs compared, $([ $fail = 0 ] && echo all identical || echo DIFFERENCES)"
exit $fail
