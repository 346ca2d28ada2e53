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
# the main window (WORK_DIR/shot.png, MeshLab's log beside it). The check is on the pixels of
# the viewer (the OpenGL widget's X window): each of the four colours, matched as a strongly
# saturated pixel of its hue, must cover at least MIN_SHARE_PERCENT of them (each quadrant is
# about 8% of the viewer at MeshLab's initial zoom), and the four must sit where the mesh has
# them (red and blue left of green and yellow, red and green above blue and yellow). A mesh
# drawn without its vertex colours (MeshLab's grey) matches none of them, nor does the viewer's
# background gradient.
#
# Exits 77 (ctest SKIP_RETURN_CODE) when meshlab, Xvfb, xdotool, xwininfo, ImageMagick or
# MeshLab's library is missing; 1 with a message when a check fails. About 10 s.
set -euo pipefail

if [ $# -lt 3 ] || [ $# -gt 4 ]; then
  echo "usage: $0 PLUGIN.so POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]" >&2
  exit 2
fi

# shellcheck source-path=SCRIPTDIR source=../../scripts/lib/meshlab_gui.sh
. "$(dirname "${BASH_SOURCE[0]}")/../../scripts/lib/meshlab_gui.sh"
PLUGIN="$(abspath "$1")"
POMAR_CLI="$(abspath "$2")"
mkdir -p "$3"
OUT_DIR="$(cd "$3" && pwd)"
mlgui_init gui_colour_test # (cd's to the repository)
SYS_MLLIB="${4:-$SYS_MLLIB}"
USE_INSTALLED=0   # the private tree (mlgui_pick_meshlab)
TIMEOUT=30        # seconds for each wait (X server, dialog, load)
MIN_SHARE_PERCENT=5

for tool in Xvfb:xvfb xdotool:xdotool xwininfo:x11-utils import:imagemagick convert:imagemagick; do
  skip_without "${tool%%:*}" "${tool%%:*} is not installed (package ${tool#*:})"
done
[ -x /usr/bin/meshlab ] || skip "/usr/bin/meshlab is not installed (package meshlab)"
skip_without_meshlab_lib "$SYS_MLLIB"
[ -f "$PLUGIN" ] || die "plugin not found: $PLUGIN"
[ -x "$POMAR_CLI" ] || die "pomar executable not found: $POMAR_CLI"

mlgui_make_workdir pomar-gui-colour
mlgui_pick_meshlab "$PLUGIN"

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
mlgui_start_xvfb
mlgui_start_meshlab "$WORK/home" "$WORK/meshlab.log" "$DATA/quadrants.pomar"
id=""
for _ in $(seq $((TIMEOUT * 5))); do
  id="$(xdotool search --name '^Pre-Open Options$' 2>/dev/null | head -n1 || true)"
  [ -n "$id" ] && break
  kill -0 "$ML_PID" 2>/dev/null || fail_log "meshlab exited before the Pre-Open Options dialog"
  sleep 0.2
done
[ -n "$id" ] || fail_log "no Pre-Open Options dialog within ${TIMEOUT}s (is the plugin loaded?)"
mlgui_answer_preopen "$id" full
for _ in $(seq $((TIMEOUT * 5))); do
  grep -q 'All files opened' "$ERRLOG" && break
  kill -0 "$ML_PID" 2>/dev/null || fail_log "meshlab exited while opening"
  sleep 0.2
done
grep -q 'All files opened' "$ERRLOG" || fail_log "the mesh did not load within ${TIMEOUT}s"
mlgui_check_opened full ""
sleep "$RENDER_WAIT"
mid="$(xdotool search --name '^MeshLab [0-9]' 2>/dev/null | head -n1 || true)"
[ -n "$mid" ] || fail_log "MeshLab main window not found"
# The viewer: the most deeply nested X window inside the main window that covers at least a
# quarter of it (the OpenGL widget), as "W H X Y" relative to the main window.
viewer="$(xwininfo -tree -id "$mid" | awk -v main="$(xwininfo -id "$mid" | awk '
    /Absolute upper-left X:/ { x = $NF } /Absolute upper-left Y:/ { y = $NF }
    /Width:/ { w = $NF } /Height:/ { h = $NF } END { print w, h, x, y }')" '
  BEGIN { split(main, m, " ") }
  match($0, /[0-9]+x[0-9]+\+-?[0-9]+\+-?[0-9]+ +\+-?[0-9]+\+-?[0-9]+$/) {
    split(substr($0, RSTART), g, /[x+ ]+/) # W H x y X Y
    depth = match($0, /[^ ]/)
    if (g[1] * g[2] * 4 >= m[1] * m[2] && depth > best) {
      best = depth; out = g[1] " " g[2] " " (g[5] - m[3]) " " (g[6] - m[4])
    }
  }
  END { print out }')"
SHOT="$OUT_DIR/shot.png"
mlgui_capture "$mid" "$SHOT" ""
cp "$ERRLOG" "$OUT_DIR/meshlab.log"
mlgui_stop_meshlab
read -r VW VH VX VY <<<"$viewer" || true
[ -n "${VY:-}" ] || die "cannot find MeshLab's viewer inside the main window (xwininfo -tree)"
log "viewer ${VW}x${VH}+${VX}+${VY} in $SHOT"

# ---- the check ----------------------------------------------------------------------------------
# Every viewer pixel classified as red, green, blue or yellow when strongly saturated (its bright
# channels at least 128, each dark one at most a quarter of the darkest bright one; for yellow
# red and green within a quarter of each other), anything else (MeshLab's grey mesh, the blue
# background gradient with red = green = blue / 2) as none. Per class: the pixel count and the
# mean position.
convert "$SHOT" -crop "${VW}x${VH}+${VX}+${VY}" +repage -depth 8 txt:- | awk -v min="$MIN_SHARE_PERCENT" '
  function classify(r, g, b,   lo) {
    if (r >= 128 && g >= 128) {
      lo = r < g ? r : g
      return (b * 4 <= lo && (r > g ? r - g : g - r) * 4 <= lo) ? "yellow" : ""
    }
    if (r >= 128) return (g * 4 <= r && b * 4 <= r) ? "red" : ""
    if (g >= 128) return (r * 4 <= g && b * 4 <= g) ? "green" : ""
    if (b >= 128) return (r * 4 <= b && g * 4 <= b) ? "blue" : ""
    return ""
  }
  /^#/ { next }
  match($0, /^[0-9]+,[0-9]+: *\([^)]*\)/) {
    pixel = substr($0, 1, RLENGTH)
    gsub(/[ ()]/, "", pixel); split(pixel, c, /[,:]/) # x y r g b
    ++total
    k = classify(c[3] + 0, c[4] + 0, c[5] + 0)
    if (k == "") next
    ++n[k]; sx[k] += c[1]; sy[k] += c[2]
  }
  END {
    if (total == 0) { print "FAIL: no pixels read from the screenshot"; exit 1 }
    bad = 0
    split("red green blue yellow", names, " ")
    for (i = 1; i <= 4; ++i) {
      k = names[i]
      if (n[k] > 0) { cx[k] = sx[k] / n[k]; cy[k] = sy[k] / n[k] }
      printf "%-6s %6d pixels (%5.2f%% of %d)", k, n[k], 100 * n[k] / total, total
      if (n[k] > 0) printf ", centre %.0f,%.0f", cx[k], cy[k]
      printf "\n"
      if (100 * n[k] < min * total) {
        printf "FAIL: %s covers less than %d%% of the viewer\n", k, min; bad = 1
      }
    }
    if (!bad) { # the quadrants where the mesh has them (y grows downwards in the image)
      if (!(cx["red"] < cx["green"] && cx["blue"] < cx["yellow"])) {
        print "FAIL: red/blue are not left of green/yellow"; bad = 1
      }
      if (!(cy["red"] < cy["blue"] && cy["green"] < cy["yellow"])) {
        print "FAIL: red/green are not above blue/yellow"; bad = 1
      }
    }
    exit bad
  }' || die "MeshLab does not draw the vertex colours of the .pomar file (screenshot: $SHOT)"
log "ok: the four vertex colours are drawn in their quadrants"
