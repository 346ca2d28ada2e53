# shellcheck shell=bash
# Sourced function library (bash) of the scripted MeshLab 2020.09 GUI sessions under Xvfb:
# scripts/gui_screenshot.sh, scripts/gui_refine_screenshots.sh and the ctest tests
# tests/io_plugin/gui_colour_test.sh, tests/io_plugin/gui_texture_test.sh and
# scripts/gui_refine_screenshots.sh --test. It builds the private MeshLab tree with
# tests/support/meshlab_tree.sh (recipe /work/shared/docs/meshlab-plugins.md section 5b).
#
# A script sources it, calls mlgui_init NAME (before any cd: it cd's to the repository) and
# mlgui_parse_args, then the steps in this order: mlgui_require_tools, mlgui_build,
# mlgui_make_workdir, mlgui_pick_meshlab, mlgui_encode_bunny, mlgui_start_xvfb; then per session
# mlgui_start_meshlab, mlgui_answer_preopen, mlgui_check_opened, mlgui_capture, mlgui_stop_meshlab.
# The screenshot tests use mlgui_open_full, mlgui_viewer and mlgui_check_quadrants in between.
# Globals set here: REPO BUILD POMAR SYS_MLLIB TIMEOUT RENDER_WAIT (mlgui_init), USE_INSTALLED
# OUTDIR (mlgui_parse_args), WORK XVFB_PID ML_PID (mlgui_make_workdir), MESHLAB
# (mlgui_pick_meshlab), DATA (mlgui_encode_bunny), DISPLAY (mlgui_start_xvfb), ERRLOG ML_PID
# (mlgui_start_meshlab). Also log, die and fail_log.

# shellcheck source-path=SCRIPTDIR source=../../tests/support/meshlab_tree.sh
. "$(dirname "${BASH_SOURCE[0]}")/../../tests/support/meshlab_tree.sh"

# mlgui_init NAME: NAME prefixes log and error lines; sets the globals below and cd's to the repository.
mlgui_init() {
  MLGUI_NAME="$1"
  REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
  cd "$REPO"
  BUILD=build
  POMAR="$BUILD/codec/pomar"
  SYS_MLLIB=/usr/lib/x86_64-linux-gnu/meshlab    # Debian's MeshLab library folder
  TIMEOUT=90      # seconds to wait for each of: the X server, a dialog, the mesh load, a filter
  # shellcheck disable=SC2034  # used by the scripts
  RENDER_WAIT=3   # seconds left to the viewer to (re)draw the mesh before a screenshot
}

log() { printf '%s: %s\n' "$MLGUI_NAME" "$*"; }
die() { printf '%s: error: %s\n' "$MLGUI_NAME" "$*" >&2; exit 1; }
# fail_log MESSAGE: the end of MeshLab's log (ERRLOG) on stderr, then die MESSAGE.
fail_log() { tail -n 30 "$ERRLOG" >&2; die "$*"; }

# mlgui_parse_args SCRIPT LAST ARGS...: [--installed] [OUTDIR] [-h|--help]; sets USE_INSTALLED and
# OUTDIR (absolute; default docs/images). --help prints lines 2..LAST of SCRIPT (its header).
mlgui_parse_args() {
  local script="$1" last="$2"
  shift 2
  USE_INSTALLED=0
  OUTDIR="$REPO/docs/images"
  while [ $# -gt 0 ]; do
    case "$1" in
      --installed) USE_INSTALLED=1 ;;
      -h|--help) sed -n "2,${last}p" "$script" | sed 's/^# \{0,1\}//'; exit 0 ;;
      -*) echo "$MLGUI_NAME: unknown option $1" >&2; exit 2 ;;
      *) OUTDIR="$1" ;;
    esac
    shift
  done
  case "$OUTDIR" in /*) ;; *) OUTDIR="$PWD/$OUTDIR" ;; esac
}

# mlgui_require_tools: dies, naming the Debian packages to install, unless the tools are there.
mlgui_require_tools() {
  local missing=() tool
  for tool in Xvfb:xvfb xdotool:xdotool import:imagemagick xwininfo:x11-utils; do
    command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool#*:}")
  done
  [ -x /usr/bin/meshlab ] || missing+=(meshlab)
  [ ${#missing[@]} -eq 0 ] ||
    die "missing tools; install them with: apt-get install -y --no-install-recommends ${missing[*]}"
}

# mlgui_build PLUGIN_TARGET...: (re)builds pomar, and the plugin targets unless --installed.
mlgui_build() {
  local targets=(pomar) what="is the MeshLab plugin"
  [ $# -eq 1 ] || what="are the MeshLab plugins"
  [ -f "$BUILD/build.ninja" ] || [ -f "$BUILD/Makefile" ] ||
    die "$BUILD/ is not configured: run scripts/demo.sh (or cmake -S . -B $BUILD -G Ninja) first"
  [ "$USE_INSTALLED" -eq 1 ] || targets+=("$@")
  log "building ${targets[*]}"
  cmake --build "$BUILD" --target "${targets[@]}" >/dev/null ||
    die "cmake --build $BUILD --target ${targets[*]} failed ($what enabled in $BUILD?)"
  [ -x "$POMAR" ] || die "$POMAR was not built"
}

# mlgui_cleanup: stops MeshLab and Xvfb if they run, removes WORK (the EXIT trap).
mlgui_cleanup() {
  if [ -n "$ML_PID" ]; then kill "$ML_PID" 2>/dev/null || true; wait "$ML_PID" 2>/dev/null || true; fi
  if [ -n "$XVFB_PID" ]; then kill "$XVFB_PID" 2>/dev/null || true; wait "$XVFB_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}

# mlgui_make_workdir PREFIX: a temp dir WORK (removed on exit, with MeshLab and Xvfb stopped).
mlgui_make_workdir() {
  WORK="$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX")"
  XVFB_PID=""
  ML_PID=""
  trap mlgui_cleanup EXIT
  trap 'exit 130' INT TERM
}

# mlgui_pick_meshlab PLUGIN...: sets MESHLAB. With --installed /usr/bin/meshlab, after checking that
# the plugins (by file name) are installed in /usr; otherwise meshlab in a private tree WORK/tree
# with the system plugins and the built PLUGIN... (absolute, or relative to the repository)
# instead of any installed plugin of the same name.
mlgui_pick_meshlab() {
  local so names=() paths=() tree="$WORK/tree"
  for so in "$@"; do
    names+=("$(basename "$so")")
    case "$so" in /*) paths+=("$so") ;; *) paths+=("$REPO/$so") ;; esac
  done
  if [ "$USE_INSTALLED" -eq 1 ]; then
    MESHLAB=/usr/bin/meshlab
    for so in "${names[@]}"; do
      [ -f "$SYS_MLLIB/plugins/$so" ] ||
        die "--installed: $SYS_MLLIB/plugins/$so not found (cmake --install $BUILD --prefix /usr)"
    done
  else
    for so in "${paths[@]}"; do [ -f "$so" ] || die "$so was not built"; done
    mltree_create "$tree" "$SYS_MLLIB" /usr/bin/meshlab meshlab
    mltree_link_stock_except "$tree" "$SYS_MLLIB" "${names[@]}"
    mltree_link "$tree" "${paths[@]}"
    MESHLAB="$tree/bin/meshlab"
  fi
  log "meshlab: $MESHLAB"
}

# mlgui_encode_bunny: encodes samples/bunny.ply into DATA/bunny.pomar (DATA=WORK/data).
mlgui_encode_bunny() {
  DATA="$WORK/data"
  mkdir -p "$DATA"
  "$POMAR" encode samples/bunny.ply "$DATA/bunny.pomar" --quiet
  log "encoded samples/bunny.ply -> bunny.pomar ($(stat -c %s "$DATA/bunny.pomar") bytes)"
}

# mlgui_start_xvfb: starts a 1600x1000 Xvfb on a free display (XVFB_PID) and exports DISPLAY.
mlgui_start_xvfb() {
  # -displayfd: Xvfb picks a free display number itself and writes it to that descriptor.
  exec 9>"$WORK/display"
  Xvfb -displayfd 9 -screen 0 1600x1000x24 -nolisten tcp >"$WORK/xvfb.log" 2>&1 &
  XVFB_PID=$!
  exec 9>&-
  for _ in $(seq $((TIMEOUT * 10))); do
    [ -s "$WORK/display" ] && break
    kill -0 "$XVFB_PID" 2>/dev/null || { cat "$WORK/xvfb.log" >&2; die "Xvfb exited"; }
    sleep 0.1
  done
  [ -s "$WORK/display" ] || die "Xvfb did not report a display within ${TIMEOUT}s"
  DISPLAY=":$(head -n1 "$WORK/display" | tr -d '[:space:]')"
  export DISPLAY
  log "Xvfb on $DISPLAY"
}

# mlgui_start_meshlab HOME LOG [FILE]: starts MESHLAB on FILE (absolute; default DATA/bunny.pomar)
# in the background (ML_PID) with a fresh HOME, its stdout and stderr in LOG (ERRLOG), in FILE's
# folder.
mlgui_start_meshlab() {
  local home="$1" file="${3:-$DATA/bunny.pomar}"
  ERRLOG="$2"
  rm -rf "$home"
  mkdir -p "$home" "$WORK/run"
  chmod 700 "$WORK/run"
  # Fresh HOME: first start, no saved settings (MeshLab writes ~/.config/VCG/*.conf).
  (cd "$(dirname "$file")" && HOME="$home" XDG_RUNTIME_DIR="$WORK/run" exec "$MESHLAB" "$file") \
    >"$ERRLOG" 2>&1 &
  ML_PID=$!
}

# mlgui_stop_meshlab: stops the MeshLab started by mlgui_start_meshlab.
mlgui_stop_meshlab() {
  kill "$ML_PID" 2>/dev/null || true
  wait "$ML_PID" 2>/dev/null || true
  ML_PID=""
}

# mlgui_answer_preopen WINDOW MODE: answers the plugin's "Pre-Open Options" dialog WINDOW with the
# keyboard. MODE is "full" (its defaults: "Open at: Full resolution") or "coarse" (Base clustered mesh).
mlgui_answer_preopen() {
  sleep 0.5   # let the dialog finish laying itself out
  xdotool windowfocus --sync "$1"
  if [ "$2" = coarse ]; then
    # Initially no widget has the focus; the tab order is "Open at" combo -> "Level N" -> Reset.
    # Tab focuses the combo, Down moves it from "Full resolution" to "Base clustered mesh".
    xdotool key Tab; sleep 0.2
    xdotool key Down; sleep 0.2
  fi
  xdotool key Return   # OK is the default button
}

# mlgui_check_opened MODE PREFIX: logs PREFIX and the plugin's "pomar: opened ... at level L of F"
# line from ERRLOG, and dies unless L is F (MODE full) or below F (MODE coarse).
mlgui_check_opened() {
  local mode="$1" line level finest
  line="$(grep -o 'pomar: opened .*' "$ERRLOG" | head -n1 || true)"
  [ -n "$line" ] || fail_log "no 'pomar: opened' line in MeshLab's log (open failed?)"
  log "$2${line#pomar: }"
  [[ "$line" =~ at\ level\ ([0-9]+)\ of\ ([0-9]+) ]] || die "cannot parse the level from: $line"
  level="${BASH_REMATCH[1]}" finest="${BASH_REMATCH[2]}"
  if [ "$mode" = full ] && [ "$level" -ne "$finest" ]; then die "expected full resolution (level $finest), got level $level"; fi
  if [ "$mode" = coarse ] && [ "$level" -ge "$finest" ]; then die "expected the base clustered mesh (below level $finest), got level $level"; fi
  return 0
}

# mlgui_capture WINDOW OUT PREFIX: saves the X window WINDOW (an id, or root) as OUT; logs it.
mlgui_capture() {
  mkdir -p "$(dirname "$2")"
  import -window "$1" "$2"
  log "$3wrote ${2#"$REPO"/} ($(identify -format '%wx%h' "$2" 2>/dev/null || echo '?'))"
}

# mlgui_open_full FILE LOG: starts MESHLAB on FILE (HOME=WORK/home, its log in LOG), answers the
# "Pre-Open Options" dialog with its defaults (full resolution), waits for the load and checks
# the plugin's "pomar: opened" line (mlgui_check_opened full).
mlgui_open_full() {
  local id=""
  mlgui_start_meshlab "$WORK/home" "$2" "$1"
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
}

# mlgui_viewer WINDOW: prints the viewer of MeshLab's main window WINDOW as "W H X Y" (relative to
# WINDOW): the most deeply nested X window inside it that covers at least a quarter of it (the
# OpenGL widget); nothing if there is none.
mlgui_viewer() {
  xwininfo -tree -id "$1" | awk -v main="$(xwininfo -id "$1" | awk '
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
    END { print out }'
}

# The awk function classify(r, g, b) of mlgui_check_quadrants and mlgui_colour_shares: "red",
# "green", "blue" or "yellow" for a strongly saturated pixel (its bright channels at least 128,
# each dark one at most a quarter of the darkest bright one; for yellow red and green within a
# quarter of each other), "" for anything else (MeshLab's grey mesh, the blue background
# gradient with red = green = blue / 2).
MLGUI_AWK_CLASSIFY='
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
'

# mlgui_colour_shares SHOT "W H X Y": the share of each colour of classify among the pixels of
# the viewer region of the screenshot SHOT, printed as "red=R green=G blue=B yellow=Y" (percent).
mlgui_colour_shares() {
  local w h x y
  read -r w h x y <<<"$2"
  convert "$1" -crop "${w}x${h}+${x}+${y}" +repage -depth 8 txt:- | awk "$MLGUI_AWK_CLASSIFY"'
    /^#/ { next }
    match($0, /^[0-9]+,[0-9]+: *\([^)]*\)/) {
      pixel = substr($0, 1, RLENGTH)
      gsub(/[ ()]/, "", pixel); split(pixel, c, /[,:]/) # x y r g b
      ++total
      k = classify(c[3] + 0, c[4] + 0, c[5] + 0)
      if (k != "") ++n[k]
    }
    END {
      if (total == 0) { print "no pixels read from the screenshot" > "/dev/stderr"; exit 1 }
      printf "red=%.2f green=%.2f blue=%.2f yellow=%.2f\n", 100 * n["red"] / total,
        100 * n["green"] / total, 100 * n["blue"] / total, 100 * n["yellow"] / total
    }'
}

# mlgui_check_quadrants SHOT "W H X Y" MIN_SHARE_PERCENT: checks the viewer region of the
# screenshot SHOT for a mesh drawn as four quadrants of pure colour: red top left, green top right,
# blue bottom left, yellow bottom right. Every pixel is classified by classify
# (MLGUI_AWK_CLASSIFY: red, green, blue, yellow or none). Each colour must cover at least MIN_SHARE_PERCENT of the viewer, and their mean positions must be
# where the quadrants are (red and blue left of green and yellow, red and green above blue and
# yellow). Prints the count and centre per colour; returns 1 after printing FAIL lines otherwise.
mlgui_check_quadrants() {
  local w h x y
  read -r w h x y <<<"$2"
  convert "$1" -crop "${w}x${h}+${x}+${y}" +repage -depth 8 txt:- | awk -v min="$3" "$MLGUI_AWK_CLASSIFY"'
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
    }'
}

# mlgui_gui_test NAME WORKDIR_PREFIX PLUGIN.so[:PLUGIN2.so...] POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]:
# the set-up of a GUI test (tests/io_plugin/gui_*_test.sh, scripts/gui_refine_screenshots.sh
# --test): the arguments checked, PLUGINS (absolute), POMAR_CLI and OUT_DIR set, the repository
# as the current folder, a private MeshLab tree with PLUGINS, and exit 77 (ctest
# SKIP_RETURN_CODE) when Xvfb, xdotool, xwininfo, ImageMagick, meshlab or MeshLab's library is
# missing.
mlgui_gui_test() {
  local name="$1" prefix="$2" so list
  shift 2
  if [ $# -lt 3 ] || [ $# -gt 4 ]; then
    echo "usage: $0 PLUGIN.so[:PLUGIN2.so...] POMAR_CLI WORK_DIR [MESHLAB_LIBDIR]" >&2
    exit 2
  fi
  PLUGINS=()
  IFS=: read -r -a list <<<"$1"
  for so in "${list[@]}"; do PLUGINS+=("$(abspath "$so")"); done
  POMAR_CLI="$(abspath "$2")"
  mkdir -p "$3"
  OUT_DIR="$(cd "$3" && pwd)"
  mlgui_init "$name" # (cd's to the repository)
  SYS_MLLIB="${4:-$SYS_MLLIB}"
  USE_INSTALLED=0 # the private tree (mlgui_pick_meshlab)
  TIMEOUT=30      # seconds for each wait (X server, dialog, load)
  local tool
  for tool in Xvfb:xvfb xdotool:xdotool xwininfo:x11-utils import:imagemagick convert:imagemagick; do
    skip_without "${tool%%:*}" "${tool%%:*} is not installed (package ${tool#*:})"
  done
  [ -x /usr/bin/meshlab ] || skip "/usr/bin/meshlab is not installed (package meshlab)"
  skip_without_meshlab_lib "$SYS_MLLIB"
  for so in "${PLUGINS[@]}"; do [ -f "$so" ] || die "plugin not found: $so"; done
  [ -x "$POMAR_CLI" ] || die "pomar executable not found: $POMAR_CLI"
  mlgui_make_workdir "$prefix"
  mlgui_pick_meshlab "${PLUGINS[@]}"
}

# mlgui_gui_session FILE: one GUI session of a GUI test (after mlgui_gui_test): MeshLab opens
# FILE at full resolution under Xvfb, the main window is captured to $OUT_DIR/shot.png
# (SHOT) and MeshLab's log copied to $OUT_DIR/meshlab.log; `viewer` is the 3D viewer's
# geometry in the capture ("W H X Y").
mlgui_gui_session() {
  mlgui_start_xvfb
  mlgui_open_full "$1" "$WORK/meshlab.log"
  sleep "$RENDER_WAIT"
  local mid
  mid="$(xdotool search --name '^MeshLab [0-9]' 2>/dev/null | head -n1 || true)"
  [ -n "$mid" ] || fail_log "MeshLab main window not found"
  viewer="$(mlgui_viewer "$mid")"
  SHOT="$OUT_DIR/shot.png"
  mlgui_capture "$mid" "$SHOT" ""
  cp "$ERRLOG" "$OUT_DIR/meshlab.log"
  mlgui_stop_meshlab
  [ -n "$viewer" ] || die "cannot find MeshLab's viewer inside the main window (xwininfo -tree)"
  log "viewer $viewer (W H X Y) in $SHOT"
}
