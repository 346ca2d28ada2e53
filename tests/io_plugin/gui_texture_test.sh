#!/usr/bin/env bash
# What MeshLab 2020.09's GUI draws for a textured .pomar file (io_plugin/).
#
#   bash tests/io_plugin/gui_texture_test.sh PLUGIN.so POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]
#
# Registered in ctest as "io_plugin_gui_texture" (tests/io_plugin/CMakeLists.txt).
# Writes a flat square facing the viewer as OBJ + MTL with per-corner texture coordinates into a
# PNG of four quadrants of pure colour, encodes it with POMAR_CLI into another folder that holds
# the .pomar file and a copy of the PNG only (the file names its texture relative to itself),
# opens it in the real `meshlab` GUI (a private tree with the system plugins and PLUGIN.so, under
# Xvfb, fresh HOME; the steps of scripts/lib/meshlab_gui.sh), accepts the "Pre-Open Options"
# dialog and takes a screenshot of the main window (WORK_DIR/shot.png, MeshLab's log beside it).
#
# The texture's halves are swapped against the square's: the left half of the image holds the
# colours of the square's right half (green above yellow) and the other way round, so the
# texture coordinates jump at the square's vertical centre line (a seam: the corners of one
# vertex there disagree, which per-vertex texture coordinates cannot express). Drawn with its
# texture, the square shows red top left, green top right, blue bottom left, yellow bottom
# right; mlgui_check_quadrants checks the viewer's pixels for that (each colour on at least
# MIN_SHARE_PERCENT of them, in its quadrant). A mesh drawn without its texture (MeshLab's grey,
# or its placeholder image for a texture it cannot load) matches none of them.
#
# Exits 77 (ctest SKIP_RETURN_CODE) when meshlab, Xvfb, xdotool, xwininfo, ImageMagick or
# MeshLab's library is missing; 1 with a message when a check fails. About 10 s.
set -euo pipefail

# shellcheck source-path=SCRIPTDIR source=../../scripts/lib/meshlab_gui.sh
. "$(dirname "${BASH_SOURCE[0]}")/../../scripts/lib/meshlab_gui.sh"
mlgui_gui_test gui_texture_test pomar-gui-texture "$@"
MIN_SHARE_PERCENT=5

# ---- the textured mesh ------------------------------------------------------------------------
# The texture, 128 x 128: top row green | red, bottom row yellow | blue.
SRC="$WORK/src"
DATA="$WORK/data"
mkdir -p "$SRC" "$DATA"
convert -size 64x64 \( xc:'#00ff00' xc:'#ff0000' +append \) \
  \( xc:'#ffff00' xc:'#0000ff' +append \) -append "$SRC/quadrants.png" ||
  die "convert cannot write the texture"
printf 'newmtl quadrants\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nmap_Kd quadrants.png\n' \
  >"$SRC/quadrants.mtl"
# An N x N grid of quads over [-1,1]^2 in the plane z = 0, counter-clockwise seen from +z (MeshLab's
# initial view), one texture coordinate per corner: v = (y + 1) / 2 (OBJ's v grows upwards in
# the image); u = x / 2 on the right half (x >= 0), 1 + x / 2 on the left one.
N=16
awk -v n="$N" 'BEGIN {
  print "mtllib quadrants.mtl"
  for (j = 0; j <= n; ++j)
    for (i = 0; i <= n; ++i)
      printf "v %g %g 0\n", -1 + 2 * i / n, -1 + 2 * j / n
  print "usemtl quadrants"
  t = 0
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      a = j * (n + 1) + i; b = a + 1; c = a + n + 1; d = c + 1
      split(a " " b " " d " " a " " d " " c, corner, " ")
      for (k = 1; k <= 6; ++k) {
        ci = corner[k] % (n + 1); cj = int(corner[k] / (n + 1))
        x = -1 + 2 * ci / n
        u = 2 * i < n ? 1 + x / 2 : x / 2 # the face decides the half, not the vertex
        printf "vt %g %g\n", u, cj / n
      }
      printf "f %d/%d %d/%d %d/%d\n", a + 1, t + 1, b + 1, t + 2, d + 1, t + 3
      printf "f %d/%d %d/%d %d/%d\n", a + 1, t + 4, d + 1, t + 5, c + 1, t + 6
      t += 6
    }
}' >"$SRC/quadrants.obj"
"$POMAR_CLI" encode --quiet "$SRC/quadrants.obj" "$DATA/quadrants.pomar" ||
  die "pomar encode failed"
cp "$SRC/quadrants.png" "$DATA/"
rm -rf "$SRC" # only the .pomar file and its texture remain

# ---- one GUI session --------------------------------------------------------------------------
mlgui_gui_session "$DATA/quadrants.pomar" # (sets viewer and SHOT)
if grep -q 'Failure of loading texture' "$OUT_DIR/meshlab.log"; then
  grep 'Failure of loading texture' "$OUT_DIR/meshlab.log" >&2
  die "MeshLab did not load the texture next to the .pomar file"
fi

# ---- the check (mlgui_check_quadrants) ----------------------------------------------------------
mlgui_check_quadrants "$SHOT" "$viewer" "$MIN_SHARE_PERCENT" ||
  die "MeshLab does not draw the texture of the .pomar file (screenshot: $SHOT)"
log "ok: the texture's four colours are drawn in their quadrants"
