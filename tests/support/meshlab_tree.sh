# shellcheck shell=bash
# Sourced function library (bash) for the MeshLab 2020.09 end-to-end scripts:
#   - mltree_*: a private MeshLab tree, recipe /work/shared/docs/meshlab-plugins.md section 5b:
#     TREE/bin/<a *copy* of the MeshLab binary>, TREE/lib/x86_64-linux-gnu/meshlab/ with a symlink to
#     libmeshlab-common.so and plugins/ with symlinks to the plugins to load, so that nothing under
#     /usr is touched and only those plugins load. Also used by scripts/lib/meshlab_gui.sh.
#   - the harness of tests/io_plugin/meshlabserver_test.sh and
#     tests/meshlab_plugin/meshlabserver_test.sh: skipping (exit 77, ctest SKIP_RETURN_CODE), the
#     private meshlabserver run under `xvfb-run -a` with a fresh HOME, and the check helpers.
# Sourcing it only defines functions and sets CHECKS=0, CUR="(setup)" and LAST_CMD="".

# ---- private MeshLab tree ------------------------------------------------------------------------------

# mltree_plugdir TREE: prints the plugins folder of the private tree TREE.
mltree_plugdir() { printf '%s\n' "$1/lib/x86_64-linux-gnu/meshlab/plugins"; }

# mltree_create TREE MLLIB EXE NAME: TREE/bin/NAME (a copy of EXE), a symlink to
# MLLIB/libmeshlab-common.so and an empty plugins folder.
mltree_create() {
  local tree="$1" mllib="$2" exe="$3" name="$4" plugdir
  plugdir="$(mltree_plugdir "$tree")"
  mkdir -p "$tree/bin" "$plugdir"
  # A copy, not a symlink: MeshLab finds its plugins from the resolved path of its binary.
  cp "$exe" "$tree/bin/$name"
  ln -s "$mllib/libmeshlab-common.so" "${plugdir%/plugins}/"
}

# mltree_link TREE SO...: symlinks each SO (at least one) into TREE's plugins folder, same name.
mltree_link() {
  local plugdir
  plugdir="$(mltree_plugdir "$1")"
  shift
  ln -s "$@" "$plugdir/"
}

# mltree_link_as TREE SO NAME: symlinks SO into TREE's plugins folder as NAME.
mltree_link_as() { ln -s "$2" "$(mltree_plugdir "$1")/$3"; }

# mltree_link_stock_except TREE MLLIB NAME...: symlinks every MLLIB/plugins/*.so into TREE's
# plugins folder but those named NAME... (the plugins the caller brings itself).
mltree_link_stock_except() {
  local tree="$1" mllib="$2" so
  shift 2
  for so in "$mllib"/plugins/*.so; do
    case " $* " in *" $(basename "$so") "*) ;; *) mltree_link "$tree" "$so" ;; esac
  done
}

# ---- arguments, skipping ------------------------------------------------------------------------------

# abspath FILE: FILE's absolute path (its folder must exist).
abspath() { echo "$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; }

# mlserver_args POMAR_CLI SAMPLES_DIR WORK_DIR [MESHLAB_LIBDIR]: the arguments both tests end with.
# Sets POMAR and SAMPLES (absolute), WORK (created, absolute) and MLLIB (default: Debian's).
# shellcheck disable=SC2034  # globals for the caller
mlserver_args() {
  POMAR="$(abspath "$1")"
  SAMPLES="$(cd "$2" && pwd)"
  mkdir -p "$3"
  WORK="$(cd "$3" && pwd)"
  MLLIB="${4:-/usr/lib/x86_64-linux-gnu/meshlab}"
}

# skip REASON: reports the test as skipped (ctest SKIP_RETURN_CODE 77).
skip() { echo "SKIP: $*"; exit 77; }

# skip_without COMMAND REASON: skips unless COMMAND is on the PATH.
skip_without() { command -v "$1" >/dev/null 2>&1 || skip "$2"; }

# skip_without_server: skips unless meshlabserver and xvfb-run are installed.
skip_without_server() {
  skip_without meshlabserver "meshlabserver is not installed"
  skip_without xvfb-run "xvfb-run is not installed (package xvfb)"
}

# skip_without_meshlab_lib MLLIB STOCK...: skips unless MLLIB holds libmeshlab-common.so and the
# stock plugins MLLIB/plugins/STOCK...
skip_without_meshlab_lib() {
  local mllib="$1" p
  shift
  [ -f "$mllib/libmeshlab-common.so" ] || skip "$mllib/libmeshlab-common.so not found"
  for p in "$@"; do
    [ -f "$mllib/plugins/$p" ] || skip "stock plugin $mllib/plugins/$p not found"
  done
}

# ---- the private meshlabserver ---------------------------------------------------------------------------

# mlserver_prepare WORK MLLIB STOCK...: a fresh WORK/tree with a copy of meshlabserver and the stock
# plugins MLLIB/plugins/STOCK..., an empty WORK/home (mode 700) and WORK/out. Sets TREE, PLUGDIR,
# ML (the private meshlabserver), OUTDIR (WORK/out) and MLHOME (WORK/home) for ml. The caller links
# its own plugins with mltree_link_as "$TREE" SO NAME.
mlserver_prepare() {
  local work="$1" mllib="$2" p
  shift 2
  TREE="$work/tree"
  # shellcheck disable=SC2034  # for the caller
  PLUGDIR="$(mltree_plugdir "$TREE")"
  ML="$TREE/bin/meshlabserver"
  OUTDIR="$work/out"
  MLHOME="$work/home"
  rm -rf "$TREE" "$MLHOME" "$OUTDIR"
  mkdir -p "$MLHOME" "$OUTDIR"
  chmod 700 "$MLHOME"
  mltree_create "$TREE" "$mllib" "$(readlink -f "$(command -v meshlabserver)")" meshlabserver
  for p in "$@"; do
    mltree_link "$TREE" "$mllib/plugins/$p"
  done
}

# ---- running commands, checks -------------------------------------------------------------------------

CHECKS=0          # checks passed so far
CUR="(setup)"     # the current section, named by fail
LAST_CMD=""       # the last command run by run_labelled (for fail)

# section TITLE: starts a section of checks.
section() { CUR="$*"; printf -- '--- %s\n' "$*"; }
# pass: counts one passed check.
pass() { CHECKS=$((CHECKS + 1)); }
# fail MESSAGE: prints what failed (with the last command, its status and output) and exits 1.
fail() {
  {
    printf 'FAIL [%s]: %s\n' "$CUR" "$*"
    if [ -n "$LAST_CMD" ]; then
      printf '  last command: %s\n  exit status : %s\n  output      :\n' "$LAST_CMD" "$RC"
      printf '%s\n' "$OUT" | fail_excerpt
    fi
  } >&2
  exit 1
}
# fail_excerpt: filters the output fail shows (stdin to stdout): its first 40 lines, indented.
# A test may define its own after sourcing this file.
fail_excerpt() { sed 's/^/    /' | head -40; }

# run_labelled LABEL COMMAND [ARGS...]: runs COMMAND; sets RC, OUT (stdout + stderr) and LAST_CMD=LABEL.
run_labelled() {
  LAST_CMD="$1"
  shift
  set +e
  OUT="$("$@" 2>&1)"
  RC=$?
  set -e
}
# run COMMAND [ARGS...]: runs a command; sets RC and OUT.
run() { run_labelled "$*" "$@"; }

# ml ARGS...: runs the private meshlabserver under Xvfb in OUTDIR with HOME=MLHOME (see
# mlserver_prepare); sets RC and OUT (stdout + stderr).
ml() {
  LAST_CMD="meshlabserver $*"
  set +e
  OUT="$(cd "$OUTDIR" && HOME="$MLHOME" XDG_RUNTIME_DIR="$MLHOME" \
    xvfb-run -a "$ML" "$@" 2>&1)"
  RC=$?
  set -e
}

expect_rc() { [ "$RC" -eq "$1" ] || fail "expected exit status $1, got $RC"; pass; }
expect_nonzero() { [ "$RC" -ne 0 ] || fail "expected a non-zero exit status, got 0"; pass; }
expect_file() { [ -s "$1" ] || fail "expected a non-empty file at $1"; pass; }
expect_no_file() { [ ! -e "$1" ] || fail "expected no file at $1, but it exists"; pass; }
expect_output() { # expect_output NEEDLE
  case "$OUT" in *"$1"*) pass ;; *) fail "the output does not contain '$1'" ;; esac
}
expect_no_output() { # expect_no_output NEEDLE
  case "$OUT" in *"$1"*) fail "the output contains '$1'" ;; *) pass ;; esac
}
