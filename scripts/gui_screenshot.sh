#!/usr/bin/env bash
# Screenshots of MeshLab 2020.09's GUI opening a .pomar file through our IO plugin (io_plugin/).
#
#   scripts/gui_screenshot.sh [--installed] [OUTDIR]
#
# Encodes samples/bunny.ply with build/codec/pomar, starts Xvfb on a free display, and runs
# `meshlab` (with a fresh HOME) on the .pomar twice:
#   1. "Pre-Open Options" dialog accepted as is ("Open at: Full resolution")
#        -> OUTDIR/meshlab_open_pomar.png
#   2. "Open at: Base clustered mesh" chosen in the dialog with the keyboard (Tab, Down, Return)
#        -> OUTDIR/meshlab_open_pomar_coarse.png
# Each screenshot is cropped to the MeshLab main window. The plugin's log line ("pomar: opened
# ... at level L of F") is checked, so a wrong choice in the dialog fails the script.
#
# By default MeshLab runs from a private tree under a temp dir (a copy of /usr/bin/meshlab, the
# system plugins plus build/io_plugin/libio_pomar.so; see /work/shared/docs/meshlab-plugins.md
# section 5b), so nothing under /usr is needed or touched. With --installed it runs
# /usr/bin/meshlab and relies on the plugin installed in /usr (e.g. by scripts/demo.sh).
#
# Needs (Debian): meshlab xvfb xdotool imagemagick x11-utils (+ libgl1-mesa-dri for software GL),
# and a configured build/ (scripts/demo.sh does that); the targets pomar and io_pomar are
# (re)built here. Works from any directory.
set -euo pipefail

# The steps shared with scripts/gui_refine_screenshots.sh: scripts/lib/meshlab_gui.sh.
# shellcheck source-path=SCRIPTDIR source=lib/meshlab_gui.sh
. "$(dirname "${BASH_SOURCE[0]}")/lib/meshlab_gui.sh"
mlgui_init gui_screenshot
mlgui_parse_args "${BASH_SOURCE[0]}" 23 "$@"   # --help: lines 2-23

mlgui_require_tools
mlgui_build io_pomar
mlgui_make_workdir pomar-gui
mlgui_pick_meshlab "$BUILD/io_plugin/libio_pomar.so"
mlgui_encode_bunny
mlgui_start_xvfb

# ---- one GUI session ----------------------------------------------------------------
# shoot MODE OUT: MODE is "full" (accept the dialog's defaults) or "coarse" (Base clustered mesh).
shoot() {
  local mode="$1" out="$2" id="" mid=""
  mlgui_start_meshlab "$WORK/home-$mode" "$WORK/meshlab-$mode.log"

  for _ in $(seq $((TIMEOUT * 5))); do
    id="$(xdotool search --name '^Pre-Open Options$' 2>/dev/null | head -n1 || true)"
    [ -n "$id" ] && break
    kill -0 "$ML_PID" 2>/dev/null || fail_log "meshlab exited before the Pre-Open Options dialog"
    sleep 0.2
  done
  [ -n "$id" ] || fail_log "no Pre-Open Options dialog within ${TIMEOUT}s (is the plugin loaded?)"
  mlgui_answer_preopen "$id" "$mode"

  for _ in $(seq $((TIMEOUT * 5))); do
    grep -q 'All files opened' "$ERRLOG" && break
    kill -0 "$ML_PID" 2>/dev/null || fail_log "meshlab exited while opening"
    sleep 0.2
  done
  grep -q 'All files opened' "$ERRLOG" || fail_log "the mesh did not load within ${TIMEOUT}s"
  mlgui_check_opened "$mode" "$mode: "
  sleep "$RENDER_WAIT"

  mid="$(xdotool search --name '^MeshLab [0-9]' 2>/dev/null | head -n1 || true)"
  if [ -z "$mid" ]; then
    log "MeshLab main window not found: saving the whole screen"
    mid=root
  fi
  mlgui_capture "$mid" "$out" ""
  mlgui_stop_meshlab
}

shoot full "$OUTDIR/meshlab_open_pomar.png"
shoot coarse "$OUTDIR/meshlab_open_pomar_coarse.png"
log "ok"
