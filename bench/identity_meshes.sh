# The meshes of the byte-identity checks (bench/identity_check.sh and
# bench/encode_identity_check.sh source this file): identity_meshes DIR NAME... fills the
# array `meshes` with samples/*.ply and samples/*.off, the files NAME... of $DATA that are
# there, the dragon (decompressed into DIR; not with $QUICK) and noisy spheres of 20k and
# 134k vertices (and 1M without $QUICK) generated into DIR by $GEN.
identity_meshes() {
  local dir=$1 f n sizes="20000 134000"
  shift
  meshes=()
  for f in "$ROOT"/samples/*.ply "$ROOT"/samples/*.off; do meshes+=("$f"); done
  for f in "$@"; do
    [ -f "$DATA/$f" ] && meshes+=("$DATA/$f")
  done
  if [ -z "$QUICK" ] && [ -f "$DATA/dragon.ply.xz" ]; then
    xz -dc "$DATA/dragon.ply.xz" >"$dir/dragon.ply" && meshes+=("$dir/dragon.ply")
  fi
  [ -z "$QUICK" ] && sizes="$sizes 1000000"
  for n in $sizes; do
    "$GEN" noisy_sphere "$n" "$dir/sphere_$n.ply" >/dev/null && meshes+=("$dir/sphere_$n.ply")
  done
  return 0
}
