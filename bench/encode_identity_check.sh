#!/usr/bin/env bash
# Byte identity of the encoder against a reference `pomar` tool: every .pomar file the new
# tool writes is compared with `cmp` to the reference's, and the exit statuses and the
# messages on stderr of refused inputs must match.
#
#   bash bench/encode_identity_check.sh REF_POMAR NEW_POMAR [--quick] [--cache DIR]
#
# Meshes: samples/*, what of /work/shared/data (or $POMAR_DATA) is present (bunny, horse
# with normals, armadillo 50k (OBJ), the photo-coloured armadillo, fertility, bimba, the
# rocker arm, dragon_res4, many_small_holes with colour, snowden, lato, the textured bunny,
# the non-manifold / cut / oblong OFF meshes, STL files, the dragon), generated noisy spheres
# of 20k, 134k and 1M vertices (--quick: no dragon, no 1M). Options: default,
# --progressive, --threads 1/2/7, --bits 4/7/16/24, --clusters 400/5000, --strict,
# --keep-order, --exact-attributes (not every option on every mesh: see `options_for`).
# --cache DIR keeps the reference's outputs between runs (the reference does not change).
# Prints one line per difference and a summary; exit status 1 if anything differs.
set -u
REF=${1:?reference pomar tool}
NEW=${2:?pomar tool to check}
shift 2
QUICK=
CACHE=
while [ $# -gt 0 ]; do
  case $1 in
  --quick) QUICK=1 ;;
  --cache)
    CACHE=$2
    shift
    ;;
  *)
    echo "unknown argument $1" >&2
    exit 2
    ;;
  esac
  shift
done
ROOT=$(cd "$(dirname "$0")/.." && pwd)
DATA=${POMAR_DATA:-/work/shared/data}
GEN=$ROOT/build/bench/pomar_gen_mesh
[ -x "$GEN" ] || GEN=$ROOT/build-test/bench/pomar_gen_mesh
W=$(mktemp -d /tmp/encode_identity.XXXXXX)
trap 'rm -rf "$W"' EXIT
[ -n "$CACHE" ] || CACHE=$W/ref
mkdir -p "$CACHE" "$W/in"
fail=0
pairs=0

check() { # label mesh args... : encode with both tools, compare file, status and stderr
  local label=$1 mesh=$2
  shift 2
  local key
  key=$(printf '%s' "$label" | tr -c 'A-Za-z0-9_.-' '_')
  local a=$CACHE/$key.pomar b=$W/new.pomar
  if [ ! -f "$CACHE/$key.status" ]; then
    rm -f "$a"
    "$REF" encode -q "$@" "$mesh" "$a" >/dev/null 2>"$W/ref.err"
    echo $? >"$CACHE/$key.status"
    sed "s|$a|OUT|g" "$W/ref.err" >"$CACHE/$key.err"
  fi
  rm -f "$b"
  "$NEW" encode -q "$@" "$mesh" "$b" >/dev/null 2>"$W/new.raw"
  local rb=$?
  sed "s|$b|OUT|g" "$W/new.raw" >"$W/new.err"
  pairs=$((pairs + 1))
  if [ "$(cat "$CACHE/$key.status")" != $rb ]; then
    echo "DIFFERENT: $label: exit status $(cat "$CACHE/$key.status") vs $rb"
    fail=1
  elif ! cmp -s "$CACHE/$key.err" "$W/new.err"; then
    echo "DIFFERENT: $label: messages differ"
    fail=1
  elif [ -f "$a" ] || [ -f "$b" ]; then
    if ! cmp -s "$a" "$b"; then
      echo "DIFFERENT: $label"
      fail=1
    fi
  fi
}

# shellcheck source=bench/identity_meshes.sh
. "$ROOT/bench/identity_meshes.sh"
identity_meshes "$W/in" bunny.ply horse.ply armadillo_50k.obj armadillo_photo_colour.ply \
  fertility_23k.off bimba_9k.off rocker_arm.off dragon_res4.ply meshlab_many_small_holes.ply \
  snowden.ply meshlab_lato315.ply meshlab_bunny10k_textured.obj meshlab_non_manif_hole.ply \
  mepp2_cube_nonman.off mepp2_cut_vertices.off cgal_oblong_shuffled.off cgal_pig.stl \
  thingi10k_100036.stl thingi10k_130976.stl trimesh_soup.stl trimesh_wallhole.obj \
  draco_test_nm.obj

options_for() { # mesh name -> one option set per line ("-" = default)
  local name=$1
  printf '%s\n' - --progressive "--threads 1" "--threads 2" "--threads 7" --strict
  case $name in
  sphere_1000000.ply | dragon.ply) return ;; # large: the thread counts are what matter
  esac
  printf '%s\n' "--bits 4" "--bits 7" "--bits 16" "--bits 24" "--clusters 400" \
    "--clusters 5000" "--progressive --bits 16" --keep-order --exact-attributes
}

for m in "${meshes[@]}"; do
  name=$(basename "$m")
  label=$(basename "$(dirname "$m")")/$name # samples/bunny.ply is not data/bunny.ply
  while read -r opts; do
    [ "$opts" = - ] && opts=
    # shellcheck disable=SC2086
    check "$label $opts" "$m" $opts
  done < <(options_for "$name")
done
echo "encode identity: $pairs encodes compared, $([ $fail = 0 ] && echo all identical || echo DIFFERENCES)"
exit $fail
