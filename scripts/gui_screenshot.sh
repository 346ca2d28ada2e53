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

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"

USE_INSTALLED=0
OUTDIR="$REPO/docs/images"
while [ $# -gt 0 ]; do
  case "$1" in
    --installed) USE_INSTALLED=1 ;;
    -h|--help) sed -n '2,23p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "gui_screenshot: unknown option $1" >&2; exit 2 ;;
    *) OUTDIR="$1" ;;
  esac
  shift
done

BUILD=build
POMAR="$BUILD/codec/pomar"
PLUGIN="$BUILD/io_plugin/libio_pomar.so"
TIMEOUT=90          # seconds to wait for each of: the X server, the dialog, the mesh load
RENDER_WAIT=3       # seconds left to the viewer to draw the mesh after the load finished

log() { printf 'gui_screenshot: %s\n' "$*"; }
die() { printf 'gui_screenshot: error: %s\n' "$*" >&2; exit 1; }

# ---- prerequisites -------------------------------------------------------------
missing=()
for tool in Xvfb:xvfb xdotool:xdotool import:imagemagick xwininfo:x11-utils; do
  command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool#*:}")
done
[ -x /usr/bin/meshlab ] || missing+=(meshlab)
[ ${#missing[@]} -eq 0 ] ||
  die "missing tools; install them with: apt-get install -y --no-install-recommends ${missing[*]}"

[ -f "$BUILD/build.ninja" ] || [ -f "$BUILD/Makefile" ] ||
  die "$BUILD/ is not configured: run scripts/demo.sh (or cmake -S . -B $BUILD -G Ninja) first"
targets=(pomar)
[ $USE_INSTALLED -eq 1 ] || targets+=(io_pomar)
log "building ${targets[*]}"
cmake --build "$BUILD" --target "${targets[@]}" >/dev/null ||
  die "cmake --build $BUILD --target ${targets[*]} failed (is the MeshLab plugin enabled in $BUILD?)"
[ -x "$POMAR" ] || die "$POMAR was not built"

# ---- temp dir, cleanup ----------------------------------------------------------
WORK="$(mktemp -d "${TMPDIR:-/tmp}/pomar-gui.XXXXXX")"
XVFB_PID=""
ML_PID=""
cleanup() {
  if [ -n "$ML_PID" ]; then kill "$ML_PID" 2>/dev/null || true; wait "$ML_PID" 2>/dev/null || true; fi
  if [ -n "$XVFB_PID" ]; then kill "$XVFB_PID" 2>/dev/null || true; wait "$XVFB_PID" 2>/dev/null || true; fi
  rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# ---- MeshLab to run ------------------------------------------------------------
if [ $USE_INSTALLED -eq 1 ]; then
  MESHLAB=/usr/bin/meshlab
  ls /usr/lib/x86_64-linux-gnu/meshlab/plugins/libio_pomar.so >/dev/null 2>&1 ||
    die "--installed: /usr/lib/x86_64-linux-gnu/meshlab/plugins/libio_pomar.so not found (cmake --install $BUILD --prefix /usr)"
else
  [ -f "$PLUGIN" ] || die "$PLUGIN was not built"
  # Private tree (meshlab-plugins.md 5b): the binary must be a copy, not a symlink, because
  # MeshLab finds its plugins from the resolved path of its executable.
  TREE="$WORK/tree"
  MLDIR="$TREE/lib/x86_64-linux-gnu/meshlab"
  mkdir -p "$TREE/bin" "$MLDIR/plugins"
  cp /usr/bin/meshlab "$TREE/bin/meshlab"
  ln -s /usr/lib/x86_64-linux-gnu/meshlab/libmeshlab-common.so "$MLDIR/"
  for so in /usr/lib/x86_64-linux-gnu/meshlab/plugins/*.so; do
    [ "$(basename "$so")" = libio_pomar.so ] || ln -s "$so" "$MLDIR/plugins/"
  done
  ln -s "$REPO/$PLUGIN" "$MLDIR/plugins/libio_pomar.so"
  MESHLAB="$TREE/bin/meshlab"
fi
log "meshlab: $MESHLAB"

# ---- input ----------------------------------------------------------------------
DATA="$WORK/data"
mkdir -p "$DATA"
"$POMAR" encode samples/bunny.ply "$DATA/bunny.pomar" --quiet
log "encoded samples/bunny.ply -> bunny.pomar ($(stat -c %s "$DATA/bunny.pomar") bytes)"

# ---- X server on a free display ----------------------------------------------------
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

# ---- one GUI session ----------------------------------------------------------------
# shoot MODE OUT: MODE is "full" (accept the dialog's defaults) or "coarse" (Base clustered mesh).
shoot() {
  local mode="$1" out="$2" home="$WORK/home-$1" errlog="$WORK/meshlab-$1.log" id="" mid="" line
  rm -rf "$home"
  mkdir -p "$home" "$WORK/run"
  chmod 700 "$WORK/run"
  # Fresh HOME: first start, no saved settings (MeshLab writes ~/.config/VCG/*.conf).
  (cd "$DATA" && HOME="$home" XDG_RUNTIME_DIR="$WORK/run" exec "$MESHLAB" "$DATA/bunny.pomar") \
    >"$errlog" 2>&1 &
  ML_PID=$!

  for _ in $(seq $((TIMEOUT * 5))); do
    id="$(xdotool search --name '^Pre-Open Options$' 2>/dev/null | head -n1 || true)"
    [ -n "$id" ] && break
    kill -0 "$ML_PID" 2>/dev/null || { tail -n 30 "$errlog" >&2; die "meshlab exited before the Pre-Open Options dialog"; }
    sleep 0.2
  done
  [ -n "$id" ] || { tail -n 30 "$errlog" >&2; die "no Pre-Open Options dialog within ${TIMEOUT}s (is the plugin loaded?)"; }
  sleep 0.5   # let the dialog finish laying itself out

  xdotool windowfocus --sync "$id"
  if [ "$mode" = coarse ]; then
    # Initially no widget has the focus; the tab order is "Open at" combo -> "Level N" -> Reset.
    # Tab focuses the combo, Down moves it from "Full resolution" to "Base clustered mesh".
    xdotool key Tab
    sleep 0.2
    xdotool key Down
    sleep 0.2
  fi
  xdotool key Return   # OK is the default button

  for _ in $(seq $((TIMEOUT * 5))); do
    grep -q 'All files opened' "$errlog" && break
    kill -0 "$ML_PID" 2>/dev/null || { tail -n 30 "$errlog" >&2; die "meshlab exited while opening"; }
    sleep 0.2
  done
  grep -q 'All files opened' "$errlog" || { tail -n 30 "$errlog" >&2; die "the mesh did not load within ${TIMEOUT}s"; }
  line="$(grep -o 'pomar: opened .*' "$errlog" | head -n1 || true)"
  [ -n "$line" ] || { tail -n 30 "$errlog" >&2; die "no 'pomar: opened' line in MeshLab's log (open failed?)"; }
  log "$mode: ${line#pomar: }"
  if [[ "$line" =~ at\ level\ ([0-9]+)\ of\ ([0-9]+) ]]; then
    local level="${BASH_REMATCH[1]}" finest="${BASH_REMATCH[2]}"
    if [ "$mode" = full ] && [ "$level" -ne "$finest" ]; then die "expected full resolution (level $finest), got level $level"; fi
    if [ "$mode" = coarse ] && [ "$level" -ge "$finest" ]; then die "expected the base clustered mesh (below level $finest), got level $level"; fi
  else
    die "cannot parse the level from: $line"
  fi
  sleep "$RENDER_WAIT"

  mid="$(xdotool search --name '^MeshLab [0-9]' 2>/dev/null | head -n1 || true)"
  mkdir -p "$(dirname "$out")"
  if [ -n "$mid" ]; then
    import -window "$mid" "$out"
  else
    log "MeshLab main window not found: saving the whole screen"
    import -window root "$out"
  fi
  log "wrote ${out#"$REPO"/} ($(identify -format '%wx%h' "$out" 2>/dev/null || echo '?'))"

  kill "$ML_PID" 2>/dev/null || true
  wait "$ML_PID" 2>/dev/null || true
  ML_PID=""
}

shoot full "$OUTDIR/meshlab_open_pomar.png"
shoot coarse "$OUTDIR/meshlab_open_pomar_coarse.png"
log "ok"
