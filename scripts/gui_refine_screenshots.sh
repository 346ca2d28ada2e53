#!/usr/bin/env bash
# Scripted MeshLab 2020.09 GUI session: selective refinement of a .pomar layer through both of
# our plugins (io_plugin/ opens the file, meshlab_plugin/ refines it), with screenshots.
#
#   scripts/gui_refine_screenshots.sh [--installed] [OUTDIR]
#
# Encodes samples/bunny.ply with build/codec/pomar, starts Xvfb on a free display and runs
# `meshlab` (fresh HOME) on the .pomar. Then, driving the GUI with xdotool like a user:
#   1. "Pre-Open Options": "Open at: Base clustered mesh" (Tab, Down, Return)
#        -> OUTDIR/meshlab_refine_before.png     the coarse base clustered bunny
#   2. Edit -> "Select Faces in a rectangular region", drag a rectangle over the head and ears
#        -> OUTDIR/meshlab_refine_selected.png   the selected faces in red
#      (if the tool cannot be started, or nothing ends up selected, the fallback is
#      Filters -> Selection -> "Conditional Vertex Selection" with (y > 0.15))
#   3. Filters -> Remeshing, Simplification and Reconstruction -> "POMAR: Refine Selected
#      Clusters", Apply (TargetLevel left at its default, the file's finest level), Close
#        -> OUTDIR/meshlab_refine_after.png      refined; the selection is the refined region
#   4. Select None (Ctrl+Shift+D, Apply), then Filters -> Color Creation and Processing ->
#      "POMAR: Show Levels", Apply
#        -> OUTDIR/meshlab_refine_levels.png     level map, blue = base level .. red = finest
# Filter dialogs are opened through the menus; when a dialog does not show up (other plugin
# set, other layout) the script falls back to MeshLab's filter search box (the magnifier at the
# right end of the toolbar). Every step is checked in MeshLab's log (stderr "LOG: ..." lines,
# the same text as the log pane), and the plugin's "POMAR: refined N clusters in X ms ..." line
# is printed. Screenshots are cropped to the MeshLab main window.
#
# Menu item and viewer positions are those of a 1600x1000 Xvfb screen without a window manager
# (the main window comes up at 0,0, 1066x724) with Debian's MeshLab 2020.09 plugin set.
#
# By default MeshLab runs from a private tree under a temp dir (a copy of /usr/bin/meshlab, the
# system plugins plus build/io_plugin/libio_pomar.so and build/meshlab_plugin/libfilter_pomar.so;
# see /work/shared/docs/meshlab-plugins.md section 5b), so nothing under /usr is needed or
# touched. With --installed it runs /usr/bin/meshlab with the plugins installed in /usr.
#
# Needs (Debian): meshlab xvfb xdotool imagemagick x11-utils (+ libgl1-mesa-dri for software GL),
# and a configured build/ (scripts/demo.sh does that); the targets pomar, io_pomar and
# filter_pomar are (re)built here. Works from any directory. Based on scripts/gui_screenshot.sh.
#
#   scripts/gui_refine_screenshots.sh --test IO.so:FILTER.so POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]
#
# is the ctest test "meshlab_plugin_gui_refine" (tests/meshlab_plugin/CMakeLists.txt): the same
# session with the given plugins and tool (nothing built), the screenshots in WORK_DIR, and a check
# of the last one's viewer pixels: the level map must be drawn, the refined region in the finest
# level's red and coarser clusters in green or yellow, each on at least MIN_SHARE_PERCENT of the
# viewer (a grey mesh, or one showing only the red selection, fails). Exits 77 (ctest
# SKIP_RETURN_CODE) when meshlab, Xvfb, xdotool, xwininfo, ImageMagick or MeshLab's library is
# missing.
set -euo pipefail

# The steps shared with scripts/gui_screenshot.sh: scripts/lib/meshlab_gui.sh.
# shellcheck source-path=SCRIPTDIR source=lib/meshlab_gui.sh
. "$(dirname "${BASH_SOURCE[0]}")/lib/meshlab_gui.sh"
TEST_MODE=0
MIN_SHARE_PERCENT=2
if [ "${1:-}" = --test ]; then
  shift
  TEST_MODE=1
  mlgui_gui_test gui_refine_test pomar-gui-refine "$@" # (the private tree with both plugins)
  POMAR="$POMAR_CLI"
  OUTDIR="$OUT_DIR"
else
  mlgui_init gui_refine_screenshots
  mlgui_parse_args "${BASH_SOURCE[0]}" 47 "$@" # --help: lines 2-47
  mlgui_require_tools
  mlgui_build io_pomar filter_pomar
  mlgui_make_workdir pomar-gui-refine
  mlgui_pick_meshlab "$BUILD/io_plugin/libio_pomar.so" "$BUILD/meshlab_plugin/libfilter_pomar.so"
fi
mlgui_encode_bunny
mlgui_start_xvfb

# ---- GUI helpers ---------------------------------------------------------------------
MAIN=""            # MeshLab main window id
MX=0 MY=0 MW=0     # its position and width

alive() { kill -0 "$ML_PID" 2>/dev/null || fail_log "meshlab exited ($*)"; }

# log_mark: the current length of MeshLab's log; log_since MARK: what was logged after it.
log_mark() { wc -l <"$ERRLOG"; }
log_since() { tail -n "+$(($1 + 1))" "$ERRLOG"; }

# wait_log MARK REGEX [SECONDS]: wait until a line matching REGEX is logged after MARK; print it.
wait_log() {
  local mark="$1" re="$2" secs="${3:-$TIMEOUT}" line=""
  for _ in $(seq $((secs * 5))); do
    line="$(log_since "$mark" | grep -E -m1 -- "$re" || true)"
    [ -n "$line" ] && { printf '%s\n' "$line"; return 0; }
    alive "waiting for /$re/"
    sleep 0.2
  done
  return 1
}

# find_window TITLE [SECONDS]: the id of a visible window with exactly that title, or nothing.
find_window() {
  local title="$1" secs="${2:-5}" id=""
  for _ in $(seq $((secs * 5))); do
    id="$(xdotool search --onlyvisible --name "^${title}\$" 2>/dev/null | head -n1 || true)"
    [ -n "$id" ] && { echo "$id"; return 0; }
    sleep 0.2
  done
  return 1
}

click() { xdotool mousemove "$(($1 + MX))" "$(($2 + MY))"; sleep 0.15; xdotool click 1; sleep "${3:-0.8}"; }

# Filter dialogs are floating docks with "Default | Help" and "Close | Apply" rows at the bottom.
dialog_button() {   # dialog_button WINDOW apply|close
  local X Y WIDTH HEIGHT SCREEN WINDOW
  eval "$(xdotool getwindowgeometry --shell "$1")"
  case "$2" in
    apply) xdotool mousemove $((X + WIDTH * 3 / 4)) $((Y + HEIGHT - 22)) ;;
    close) xdotool mousemove $((X + WIDTH / 4)) $((Y + HEIGHT - 22)) ;;
  esac
  sleep 0.15
  xdotool click 1
  sleep 0.5
}

close_menus() { xdotool key Escape; sleep 0.2; xdotool key Escape; sleep 0.2; xdotool key Escape; sleep 0.3; }

# open_filter NAME [CATX CATY ITEMX ITEMY]: open the parameter dialog of the filter NAME through
# Filters -> category (CATX,CATY) -> item (ITEMX,ITEMY) (window coordinates), or, without
# coordinates or when no dialog appears, through the filter search box. Prints the dialog's id.
open_filter() {
  local name="$1" id=""
  if [ $# -ge 5 ]; then
    click 121 10            # "Filters" in the menu bar
    click "$2" "$3" 1       # the category: its submenu opens on click
    click "$4" "$5" 0.5     # the filter
    id="$(find_window "$name" 5 || true)"
    if [ -n "$id" ]; then log "  opened '$name' from the Filters menu" >&2; echo "$id"; return 0; fi
    log "  no '$name' dialog from the Filters menu: using the filter search box" >&2
    close_menus
  fi
  click $((MW - 21)) 46 0.8         # the magnifier at the right end of the toolbar
  xdotool type --delay 40 "$name"
  sleep 1
  xdotool key Down; sleep 0.3; xdotool key Return   # first match
  id="$(find_window "$name" 10 || true)"
  [ -n "$id" ] || { import -window root "$WORK/no-dialog.png" 2>/dev/null || true; fail_log "cannot open the '$name' dialog"; }
  log "  opened '$name' from the filter search box" >&2
  echo "$id"
}

# apply_filter NAME REGEX: Apply in NAME's open dialog DLG, wait for REGEX (or a failure) in the
# log, dismiss a "Filter Failure" box; prints the matching line, returns 1 on failure.
apply_filter() {
  local name="$1" re="$2" dlg="$3" mark line box
  mark="$(log_mark)"
  dialog_button "$dlg" apply
  line="$(wait_log "$mark" "$re|Applied filter $name|[Ff]ailure|nothing selected|cannot " "$TIMEOUT")" ||
    fail_log "no reaction to Apply in '$name' within ${TIMEOUT}s"
  # The plugin's own line comes before MeshLab's "Applied filter": wait for the later one.
  wait_log "$mark" "Applied filter $name|[Ff]ailure|nothing selected|cannot " 10 >/dev/null || true
  line="$(log_since "$mark" | grep -E -m1 -- "$re" || true)"
  box="$(find_window 'Filter Failure' 1 || true)"
  if [ -n "$box" ]; then
    xdotool windowfocus --sync "$box" 2>/dev/null || true
    xdotool key Return; sleep 0.5
  fi
  if [ -z "$line" ]; then
    log "  '$name' failed:" >&2; log_since "$mark" | grep '^LOG' | sed 's/^/    /' >&2
    return 1
  fi
  printf '%s\n' "$line"
}

shot() {   # shot OUT: the main window, after letting the viewer redraw
  sleep "$RENDER_WAIT"
  mlgui_capture "$MAIN" "$1" "  "
}

# select_rect: Edit -> "Select Faces in a rectangular region", drag over the head. 0 if started.
select_rect() {
  local mark
  mark="$(log_mark)"
  click 74 10                 # "Edit"
  click 197 359               # "Select Faces in a rectagular region" (sic in MeshLab's log)
  if ! wait_log "$mark" 'Started Mode Select Faces in a rect' 5 >/dev/null; then
    close_menus
    return 1
  fi
  # The default view of the bunny: head and ears between (130,195) and (340,370) in the
  # 648x620 viewer at (0,70). Drag from above-left of the head to below the ears' base.
  local x0=110 y0=215 x1=350 y1=335 x
  xdotool mousemove $((MX + x0)) $((MY + y0)); sleep 0.2
  xdotool mousedown 1; sleep 0.1
  for x in 150 190 230 270 310 $x1; do
    xdotool mousemove $((MX + x)) $((MY + y0 + (x - x0) * (y1 - y0) / (x1 - x0))); sleep 0.08
  done
  sleep 0.3
  xdotool mouseup 1
  sleep 0.5
  return 0
}

# select_conditional: Filters -> Selection -> Conditional Vertex Selection, (y > 0.15).
select_conditional() {
  # shellcheck disable=SC2034  # SCREEN and WINDOW: set by the eval below, unused
  local dlg X Y WIDTH HEIGHT SCREEN WINDOW line
  dlg="$(open_filter 'Conditional Vertex Selection')"
  eval "$(xdotool getwindowgeometry --shell "$dlg")"
  xdotool mousemove $((X + WIDTH * 5 / 8)) $((Y + HEIGHT - 123)) click --repeat 3 1   # "boolean function"
  sleep 0.2; xdotool key ctrl+a; xdotool type --delay 30 '(y > 0.15)'; sleep 0.3
  line="$(apply_filter 'Conditional Vertex Selection' 'selected [0-9]+ vertices' "$dlg")" ||
    fail_log "Conditional Vertex Selection failed"
  log "  ${line#LOG: [0-9] }"
  dialog_button "$dlg" close
}

# ---- the session ----------------------------------------------------------------------
mlgui_start_meshlab "$WORK/home" "$WORK/meshlab.log"

log "1. open at the base clustered mesh"
id="$(find_window 'Pre-Open Options' "$TIMEOUT" || true)"
alive "before the Pre-Open Options dialog"
[ -n "$id" ] || fail_log "no Pre-Open Options dialog within ${TIMEOUT}s (is the plugin loaded?)"
mlgui_answer_preopen "$id" coarse
wait_log 0 'All files opened' "$TIMEOUT" >/dev/null || fail_log "the mesh did not load within ${TIMEOUT}s"
mlgui_check_opened coarse "  "
MAIN="$(find_window 'MeshLab [0-9].*' 10 || true)"
[ -n "$MAIN" ] || fail_log "MeshLab main window not found"
eval "$(xdotool getwindowgeometry --shell "$MAIN" | sed 's/^/G_/')"
MX=$G_X MY=$G_Y MW=$G_WIDTH
log "  main window ${G_WIDTH}x${G_HEIGHT} at ${MX},${MY}"
xdotool windowfocus --sync "$MAIN" 2>/dev/null || true
shot "$OUTDIR/meshlab_refine_before.png"

log "2. select the head"
SELECTION=rect
if select_rect; then
  log "  Edit -> Select Faces in a rectangular region: dragged a rectangle over the head"
  shot "$OUTDIR/meshlab_refine_selected.png"
else
  log "  the rectangle selection tool did not start: Conditional Vertex Selection instead"
  SELECTION=conditional
  select_conditional
  shot "$OUTDIR/meshlab_refine_selected.png"
fi

log "3. POMAR: Refine Selected Clusters"
REFINE='POMAR: Refine Selected Clusters'
refine() {   # 0: refined; 1: the filter failed (e.g. nothing selected); 2: no dialog
  local dlg line
  # Filters -> "Remeshing, Simplification and Reconstruction" -> "POMAR: Refine Selected Clusters"
  dlg="$(open_filter "$REFINE" 275 161 646 437)" || return 2
  line="$(apply_filter "$REFINE" 'POMAR: refined ' "$dlg")" || { dialog_button "$dlg" close; return 1; }
  dialog_button "$dlg" close
  printf '%s\n' "$line"
}
rc=0
line="$(refine)" || rc=$?
if [ $rc -eq 1 ] && [ "$SELECTION" = rect ]; then
  log "  nothing usable selected by the rectangle: Conditional Vertex Selection instead"
  SELECTION=conditional
  select_conditional
  shot "$OUTDIR/meshlab_refine_selected.png"
  rc=0
  line="$(refine)" || rc=$?
fi
[ $rc -eq 0 ] || fail_log "$REFINE failed"
line="${line#LOG: [0-9] }"
log "  $line"
[[ "$line" =~ refined\ ([0-9]+)\ clusters\ in\ ([0-9.]+)\ ms ]] && REFINE_MS="${BASH_REMATCH[2]}" && REFINED="${BASH_REMATCH[1]}"
shot "$OUTDIR/meshlab_refine_after.png"

log "4. Select None, POMAR: Show Levels"
xdotool windowfocus --sync "$MAIN" 2>/dev/null || true
xdotool key ctrl+shift+d    # Filters -> Selection -> Select None
dlg="$(find_window 'Select None' 5 || true)"
[ -n "$dlg" ] || dlg="$(open_filter 'Select None')"
apply_filter 'Select None' 'Applied filter Select None' "$dlg" >/dev/null || fail_log "Select None failed"
dialog_button "$dlg" close
# Filters -> "Color Creation and Processing" -> "POMAR: Show Levels"
dlg="$(open_filter 'POMAR: Show Levels' 223 211 607 387)"
line="$(apply_filter 'POMAR: Show Levels' 'POMAR: levels shown' "$dlg")" || fail_log "POMAR: Show Levels failed"
dialog_button "$dlg" close
log "  ${line#LOG: [0-9] }"
shot "$OUTDIR/meshlab_refine_levels.png"
VIEWER="$(mlgui_viewer "$MAIN")"

mlgui_stop_meshlab
if [ "$TEST_MODE" -eq 1 ]; then
  [ -n "$VIEWER" ] || die "cannot find MeshLab's viewer inside the main window (xwininfo -tree)"
  shares="$(mlgui_colour_shares "$OUTDIR/meshlab_refine_levels.png" "$VIEWER")" ||
    die "cannot read $OUTDIR/meshlab_refine_levels.png"
  log "level map colours in the viewer ($VIEWER): $shares"
  read -r red green yellow <<<"$(sed -E 's/red=([0-9.]+) green=([0-9.]+) blue=[0-9.]+ yellow=([0-9.]+)/\1 \2 \3/' <<<"$shares")"
  awk -v r="$red" -v g="$green" -v y="$yellow" -v min="$MIN_SHARE_PERCENT" \
    'BEGIN { exit !(r >= min && g + y >= min) }' ||
    die "MeshLab does not draw the level map (finest red and coarser green/yellow on ${MIN_SHARE_PERCENT}% each; screenshot: $OUTDIR/meshlab_refine_levels.png)"
fi
log "ok: selection by $SELECTION; refined ${REFINED:-?} clusters in ${REFINE_MS:-?} ms (plugin's log)"
