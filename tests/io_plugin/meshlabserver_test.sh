#!/usr/bin/env bash
# End-to-end test of the MeshLab IO plugin libio_pomar.so through meshlabserver 2020.09.
#
#   bash tests/io_plugin/meshlabserver_test.sh PLUGIN.so POMAR_CLI SAMPLES_DIR WORK_DIR [MESHLAB_LIBDIR]
#
# Registered in ctest as "io_plugin_meshlabserver" (tests/io_plugin/CMakeLists.txt).
# Builds a private MeshLab tree in WORK_DIR (recipe /work/shared/docs/meshlab-plugins.md, 5b:
# a *copy* of meshlabserver in tree/bin, symlinks to libmeshlab-common.so, the stock plugins
# libio_base.so + libfilter_select.so and ours), so nothing under /usr is touched and only
# these plugins load. meshlabserver needs an X display: every call runs under `xvfb-run -a`
# with HOME in WORK_DIR. The tree, the meshlabserver runs and the check helpers come from
# tests/support/meshlab_tree.sh.
#
# meshlabserver exits 0 even when a save fails, so every check looks at the files and the
# output. Exits 77 (ctest SKIP_RETURN_CODE) when meshlabserver, xvfb-run or MeshLab's library
# is missing. The first failing check prints what failed and exits 1.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=../support/meshlab_tree.sh
. "$(dirname "${BASH_SOURCE[0]}")/../support/meshlab_tree.sh"

if [ $# -lt 4 ] || [ $# -gt 5 ]; then
  echo "usage: $0 PLUGIN.so POMAR_CLI SAMPLES_DIR WORK_DIR [MESHLAB_LIBDIR]" >&2
  exit 2
fi
PLUGIN="$(abspath "$1")"
mlserver_args "${@:2}"   # POMAR SAMPLES WORK MLLIB
STOCK=(libio_base.so libfilter_select.so)

skip_without_server
skip_without_meshlab_lib "$MLLIB" "${STOCK[@]}"
[ -f "$PLUGIN" ] || { echo "FAIL: plugin not found: $PLUGIN" >&2; exit 1; }
[ -x "$POMAR" ] || { echo "FAIL: pomar executable not found: $POMAR" >&2; exit 1; }
BUNNY="$SAMPLES/bunny.ply"
NONMANIFOLD="$SAMPLES/tetra_nonmanifold.off"
for f in "$BUNNY" "$NONMANIFOLD"; do
  [ -f "$f" ] || { echo "FAIL: samples missing in $SAMPLES" >&2; exit 1; }
done

# ---- the private MeshLab tree (tests/support/meshlab_tree.sh), checks ----------------------------------

mlserver_prepare "$WORK" "$MLLIB" "${STOCK[@]}"
mltree_link_as "$TREE" "$PLUGIN" libio_pomar.so

# pomar ARGS...: runs the pomar CLI; sets RC and OUT.
pomar() { run_labelled "pomar $*" "$POMAR" "$@"; }
expect_dir_only() { # expect_dir_only NAME...: OUTDIR holds exactly these entries (no stray temp files)
  local got want
  got="$(find "$OUTDIR" -mindepth 1 -maxdepth 1 -printf '%f\n' | LC_ALL=C sort | tr '\n' ' ')"
  want="$(printf '%s\n' "$@" | LC_ALL=C sort | tr '\n' ' ')"
  [ "$got" = "$want" ] || fail "$OUTDIR holds '$got', expected exactly '$want'"
  pass
}

# ---- 1. round trip bunny.ply -> .pomar -> .ply, lossless --------------------------------------------

section "meshlabserver saves bunny.ply as .pomar"
ml -i "$BUNNY" -o bunny.pomar
expect_rc 0
expect_output "Current Plugins Dir is: $PLUGDIR"
expect_file "$OUTDIR/bunny.pomar"
expect_no_output "NOT been saved"
# bunny.ply has 1113 vertices no face uses: the file keeps them (lossless record).
expect_no_output "unreferenced vertices"
expect_dir_only bunny.pomar

section "meshlabserver opens bunny.pomar (full resolution) and saves a PLY"
ml -i bunny.pomar -o bunny_back.ply
expect_rc 0
expect_output "bunny.pomar loaded has 35947 vn 69451 fn"
expect_file "$OUTDIR/bunny_back.ply"

section "pomar verify: bunny.ply == bunny.pomar == bunny_back.ply"
pomar verify "$BUNNY" "$OUTDIR/bunny.pomar" "$OUTDIR/bunny_back.ply"
expect_rc 0
expect_output "OK"

section "a pure progressive file written by the CLI opens at full resolution"
pomar encode -q --progressive "$BUNNY" "$OUTDIR/prog.pomar"
expect_rc 0
ml -i prog.pomar -o prog_back.ply
expect_rc 0
expect_file "$OUTDIR/prog_back.ply"
pomar verify "$BUNNY" "$OUTDIR/prog.pomar" "$OUTDIR/prog_back.ply"
expect_rc 0
rm -f "$OUTDIR"/prog*

section "colors and normals not in the save mask are named in the warning"
cat >"$OUTDIR/octa.ply" <<'EOF'
ply
format ascii 1.0
element vertex 6
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
property uchar alpha
element face 8
property list uchar int vertex_indices
end_header
1 0 0 0 0 1 255 0 0 255
-1 0 0 0 0 1 0 255 0 255
0 1 0 0 0 1 0 0 255 255
0 -1 0 0 0 1 255 255 0 255
0 0 1 0 0 1 0 255 255 255
0 0 -1 0 0 1 255 0 255 255
3 0 2 4
3 2 1 4
3 1 3 4
3 3 0 4
3 2 0 5
3 1 2 5
3 3 1 5
3 0 3 5
EOF
ml -i octa.ply -o octa.pomar
expect_rc 0
expect_file "$OUTDIR/octa.pomar"
expect_output "per-vertex colors (tick Color in the save dialog / meshlabserver -m vc)"
expect_output "per-vertex normals (tick Normal / -m vn)"
pomar verify "$OUTDIR/octa.ply" "$OUTDIR/octa.pomar"
expect_rc 3 # the file lacks the colours and normals of the original
expect_output "not in the file"
pomar verify --drop colour,normals "$OUTDIR/octa.ply" "$OUTDIR/octa.pomar"
expect_rc 0

section "-m vc vn: colours exact and normals within their bound after save and open"
ml -i octa.ply -o octa.pomar -m vc vn
expect_rc 0
expect_no_output "per-vertex colors"
expect_no_output "per-vertex normals"
pomar info "$OUTDIR/octa.pomar"
expect_output "attribute colour"
expect_output "attribute normal"
ml -i octa.pomar -o octa_back.ply -m vc vn
expect_rc 0
pomar verify "$OUTDIR/octa.ply" "$OUTDIR/octa.pomar" "$OUTDIR/octa_back.ply"
expect_rc 0
expect_output "colour 'colour': RGBA, 8 bits exact, max error 0"
rm -f "$OUTDIR"/octa*

# ---- 1b. wedge texture coordinates (-m wt) ----------------------------------------------------------
# The input is samples/textured_sphere.obj as a PLY with per-face texcoord lists and texnumber
# (written by `pomar decode`): MeshLab 2020.09's OBJ importer aborts on an OBJ with vt lines
# (an assertion in vcglib's import_obj.h), so the textured input goes in as PLY.

section "-m wt: a PLY with wedge texture coordinates saves them, the face textures and the texture name"
pomar encode -q "$SAMPLES/textured_sphere.obj" "$OUTDIR/tex_src.pomar"
expect_rc 0
pomar decode -q "$OUTDIR/tex_src.pomar" "$OUTDIR/tex.ply"
expect_rc 0
rm -f "$OUTDIR/tex_src.pomar"
ml -i tex.ply -o tex.pomar -m wt
expect_rc 0
expect_file "$OUTDIR/tex.pomar"
expect_no_output "per-wedge texture coordinates"
expect_no_output "texture(s)"
pomar info "$OUTDIR/tex.pomar"
expect_output "per-corner texture coordinates"
expect_output "face materials"
expect_output "texture file textured_sphere.png"
pomar verify "$OUTDIR/tex.ply" "$OUTDIR/tex.pomar"
expect_rc 0
expect_output "face materials: 2 materials, the same per face"

section "-m wt: the .pomar opens with its wedge texture coordinates and texture name"
ml -i tex.pomar -o tex_back.ply -m wt
expect_rc 0
expect_output "tex.pomar loaded has 222 vn 440 fn"
expect_file "$OUTDIR/tex_back.ply"
run grep -a -c -e "comment TextureFile textured_sphere.png" -e "property list uchar float texcoord" \
  "$OUTDIR/tex_back.ply"
expect_output "2"
# MeshLab's PLY writer leaves out texnumber (which faces have no texture): all but the face
# materials match.
pomar verify "$OUTDIR/tex.ply" "$OUTDIR/tex.pomar" "$OUTDIR/tex_back.ply"
expect_output "the face materials of the original are missing from the decoded mesh"
expect_no_output "texture coordinates of the original are missing"

section "without -m wt the warning names the wedge texture coordinates and the texture"
ml -i tex.ply -o tex_plain.pomar
expect_rc 0
expect_output "per-wedge texture coordinates (tick TexCoord under Wedge / -m wt)"
expect_output "1 texture(s)"
pomar info "$OUTDIR/tex_plain.pomar"
expect_no_output "pomar:corner texcoord"
rm -f "$OUTDIR"/tex*

# ---- 2. a non-manifold mesh is saved exactly (the cut is stored), and opens as it was ------------

section "saving a non-manifold mesh works and keeps it exactly"
ml -i "$NONMANIFOLD" -o tetra.pomar
expect_rc 0
expect_no_output "NOT been saved"
expect_file "$OUTDIR/tetra.pomar"
pomar verify "$NONMANIFOLD" "$OUTDIR/tetra.pomar"
expect_rc 0
ml -i tetra.pomar -o tetra_back.ply
expect_rc 0
expect_output "tetra.pomar loaded has 6 vn 8 fn"
pomar verify "$NONMANIFOLD" "$OUTDIR/tetra.pomar" "$OUTDIR/tetra_back.ply"
expect_rc 0
rm -f "$OUTDIR"/tetra*
expect_dir_only bunny.pomar bunny_back.ply

# ---- 3. damaged input: a clear message, no output ---------------------------------------------------

size="$(wc -c <"$OUTDIR/bunny.pomar" | tr -d ' ')"

section "a truncated .pomar fails to open"
head -c "$((size / 2))" "$OUTDIR/bunny.pomar" >"$OUTDIR/trunc.pomar"
ml -i trunc.pomar -o trunc.ply
expect_nonzero
expect_output "Failed loading of $OUTDIR/trunc.pomar"
expect_output "truncated .pomar file"
expect_no_file "$OUTDIR/trunc.ply"

section "a .pomar cut inside its header fails to open"
head -c 100 "$OUTDIR/bunny.pomar" >"$OUTDIR/trunc.pomar"
ml -i trunc.pomar -o trunc.ply
expect_nonzero
expect_output "truncated .pomar file"
expect_no_file "$OUTDIR/trunc.ply"

section "a corrupted byte in the cluster data fails to open"
cp "$OUTDIR/bunny.pomar" "$OUTDIR/bad.pomar"
# Flip one byte 3/4 into the file (cluster blocks, protected by checksums).
python3 - "$OUTDIR/bad.pomar" <<'EOF'
import sys
p = sys.argv[1]
b = bytearray(open(p, 'rb').read())
b[len(b) * 3 // 4] ^= 0x5A
open(p, 'wb').write(b)
EOF
ml -i bad.pomar -o bad.ply
expect_nonzero
expect_output "damaged .pomar file"
expect_no_file "$OUTDIR/bad.ply"
rm -f "$OUTDIR/trunc.pomar" "$OUTDIR/bad.pomar"
expect_dir_only bunny.pomar bunny_back.ply

echo "PASS: $CHECKS checks"
