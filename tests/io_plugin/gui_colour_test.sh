#!/usr/bin/env bash
# What MeshLab 2020.09's GUI draws for a .pomar file with per-vertex colour (io_plugin/).
#
#   bash tests/io_plugin/gui_colour_test.sh PLUGIN.so POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]
#
# Registered in ctest as "io_plugin_gui_colour" (tests/io_plugin/CMakeLists.txt).
# Writes a flat square facing the viewer, split into four quadrants of pure colour (red, green,
# blue, yellow per vertex), encodes it with POMAR_CLI, opens it in the real `meshlab` GUI (a
# private tree with the system plugins and PLUGIN.so, under Xvfb, fresh HOME; the steps of
# scripts/lib/meshlab_gui.sh), accepts the "Pre-Open Options" dialog and takes a screenshot of
# the main window (WORK_DIR/shot.png, MeshLab's log beside it). The check (mlgui_check_quadrants)
# is on the pixels of the viewer (the OpenGL widget's X window): each of the four colours,
# matched as a strongly saturated pixel of its hue, must cover at least MIN_SHARE_PERCENT of them
# (each quadrant is about 8% of the viewer at MeshLab's initial zoom), and the four must sit
# where the mesh has them (red and blue left of green and yellow, red and green above blue and
# yellow). A mesh drawn without its vertex colours (MeshLab's grey) matches none of them, nor
# does the viewer's background gradient.
#
# Exits 77 (ctest SKIP_RETURN_CODE) when meshlab, Xvfb, xdotool, xwininfo, ImageMagick or
# MeshLab's library is missing; 1 with a message when a check fails. About 10 s.
set -euo pipefail

# shellcheck source-path=SCRIPTDIR source=../../scripts/lib/meshlab_gui.sh
. "$(dirname "${BASH_SOURCE[0]}")/../../scripts/lib/meshlab_gui.sh"
mlgui_gui_test gui_colour_test pomar-gui-colour "$@"
MIN_SHARE_PERCENT=5

# ---- the coloured mesh ------------------------------------------------------------------------
# An N x N grid of quads over [-1,1]^2 in the plane z = 0, counter-clockwise seen from +z (MeshLab's
# initial view). Vertex colours by quadrant: x<0,y>0 red; x>0,y>0 green; x<0,y<0 blue; x>0,y<0
# yellow (the vertices on the axes take the quadrant of their upper right neighbour).
N=16
DATA="$WORK/data"
mkdir -p "$DATA"
awk -v n="$N" 'BEGIN {
  printf "ply\nformat ascii 1.0\nelement vertex %d\n", (n + 1) * (n + 1)
  printf "property float x\nproperty float y\nproperty float z\n"
  printf "property uchar red\nproperty uchar green\nproperty uchar blue\n"
  printf "element face %d\nproperty list uchar int vertex_indices\nend_header\n", 2 * n * n
  for (j = 0; j <= n; ++j)
    for (i = 0; i <= n; ++i) {
      x = -1 + 2 * i / n; y = -1 + 2 * j / n
      if (2 * i < n && 2 * j >= n) c = "255 0 0"
      else if (2 * j >= n) c = "0 255 0"
      else if (2 * i < n) c = "0 0 255"
      else c = "255 255 0"
      printf "%g %g 0 %s\n", x, y, c
    }
  for (j = 0; j < n; ++j)
    for (i = 0; i < n; ++i) {
      a = j * (n + 1) + i; b = a + 1; c = a + n + 1; d = c + 1
      printf "3 %d %d %d\n3 %d %d %d\n", a, b, d, a, d, c
    }
}' >"$DATA/quadrants.ply"
"$POMAR_CLI" encode --quiet "$DATA/quadrants.ply" "$DATA/quadrants.pomar" ||
  die "pomar encode failed"

# ---- one GUI session --------------------------------------------------------------------------
mlgui_gui_session "$DATA/quadrants.pomar" # (sets viewer and SHOT)

# ---- the check (mlgui_check_quadrants) ----------------------------------------------------------
mlgui_check_quadrants "$SHOT" "$viewer" "$MIN_SHARE_PERCENT" ||
  die "MeshLab does not draw the vertex colours of the .pomar file (screenshot: $SHOT)"
log "ok: the four vertex colours are drawn in their quadrants"
