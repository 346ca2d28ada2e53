#!/usr/bin/env bash
# Sets up a Debian bookworm machine for building and testing pomar.
#
#  1. installs the build/test packages from Debian's archive (only if missing)
#  2. adds a deb-src entry for bookworm main (only if no deb-src entry exists)
#  3. fetches MeshLab 2020.09's Debian source package (src/common + vcglib headers)
#     into third_party/meshlab/meshlab-2020.09+dfsg1 (only if not already there)
#
# Idempotent: when everything is present it does no apt work and takes well under a second.
# Must run as root (or with passwordless sudo) when something has to be installed.
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ML_VER_DIR="meshlab-2020.09+dfsg1"
ML_PARENT="$REPO/third_party/meshlab"
ML_TREE="$ML_PARENT/$ML_VER_DIR"
SRC_LIST=/etc/apt/sources.list.d/pomar-src.sources

PACKAGES=(
  g++ cmake ninja-build pkg-config dpkg-dev xz-utils ca-certificates
  qtbase5-dev libqt5opengl5-dev libeigen3-dev libglew-dev
  libgtest-dev libgmock-dev
  meshlab xvfb xauth libgl1-mesa-dri   # mesa swrast: without it meshlabserver aborts under Xvfb (GLEW: Missing GL version)
  libcli11-dev nlohmann-json3-dev libtinyobjloader-dev libxxhash-dev zlib1g-dev
  draco libdraco-dev
  time python3 clang
  pybind11-dev python3-dev python3-numpy python3-pytest   # the Python module (python/) and its tests
  imagemagick x11-utils xdotool        # scripts/gui_screenshot.sh (GUI checks under Xvfb)
  emscripten nodejs chromium           # web/: the WebAssembly decoder and its browser test
  nginx-light apache2                  # web/test/real_servers.sh: the client against real web servers
)

log() { printf 'setup: %s\n' "$*"; }

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=(sudo); fi
fi

tree_ok() {
  [ -f "$ML_TREE/src/common/interfaces.h" ] && [ -f "$ML_TREE/vcglib/vcg/complex/complex.h" ]
}

# ---- step 1: packages -------------------------------------------------------
missing=()
for p in "${PACKAGES[@]}"; do
  st="$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null || true)"
  [ "${st:0:2}" = "ii" ] || missing+=("$p")
done
# npm (web/build.sh installs three.js for the viewer page): Debian's nodejs has it as a
# separate package; other builds of nodejs (e.g. NodeSource's) bring their own.
command -v npm >/dev/null 2>&1 || missing+=(npm)

has_deb_src() {
  # one-line style (sources.list, *.list) or deb822 style (*.sources)
  grep -Eqs '^[[:space:]]*deb-src[[:space:]]' /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null && return 0
  grep -Eqs '^[[:space:]]*Types:.*\bdeb-src\b' /etc/apt/sources.list.d/*.sources 2>/dev/null && return 0
  return 1
}

has_sources_index() {
  compgen -G '/var/lib/apt/lists/*_source_Sources*' >/dev/null
}

need_tree=0
tree_ok || need_tree=1

# ---- step 2 first (cheap), so that one apt-get update covers steps 1 and 3 ----
added_src=0
if ! has_deb_src; then
  "${SUDO[@]}" tee "$SRC_LIST" >/dev/null <<'EOF2'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF2
  added_src=1
fi

need_update=0
[ ${#missing[@]} -gt 0 ] && need_update=1
if [ $need_tree -eq 1 ] && { [ $added_src -eq 1 ] || ! has_sources_index; }; then need_update=1; fi
if [ $need_update -eq 1 ]; then
  log "apt-get update"
  "${SUDO[@]}" apt-get update -qq
fi

# ---- step 1: packages -------------------------------------------------------
if [ ${#missing[@]} -gt 0 ]; then
  log "step 1/3 packages: installing ${missing[*]}"
  "${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive \
    apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  log "step 1/3 packages: all ${#PACKAGES[@]} installed"
fi

# ---- step 2: report -----------------------------------------------------------
if [ $added_src -eq 1 ]; then
  log "step 2/3 deb-src: added $SRC_LIST"
else
  log "step 2/3 deb-src: entry already present"
fi

# ---- step 3: MeshLab source -------------------------------------------------
if [ $need_tree -eq 1 ]; then
  log "step 3/3 meshlab source: fetching with apt-get source meshlab"
  tmp="$(mktemp -d)"
  trap 'rm -rf "$tmp"' EXIT
  # apt-get source as root warns that the download is unsandboxed (user _apt); harmless.
  (cd "$tmp" && apt-get source -q meshlab >"$tmp/apt-source.log" 2>&1) || {
    cat "$tmp/apt-source.log" >&2
    echo "setup: apt-get source meshlab failed" >&2
    exit 1
  }
  if [ ! -d "$tmp/$ML_VER_DIR" ]; then
    cat "$tmp/apt-source.log" >&2
    echo "setup: expected $ML_VER_DIR after apt-get source; got: $(ls "$tmp")" >&2
    exit 1
  fi
  mkdir -p "$ML_PARENT"
  rm -rf "$ML_TREE"
  mv "$tmp/$ML_VER_DIR" "$ML_TREE"
  rm -rf "$tmp"
  trap - EXIT
  tree_ok || { echo "setup: $ML_TREE lacks src/common/interfaces.h or vcglib" >&2; exit 1; }
  log "step 3/3 meshlab source: unpacked to ${ML_TREE#"$REPO"/}"
else
  log "step 3/3 meshlab source: present at ${ML_TREE#"$REPO"/}"
fi

# keep the fetched tree out of git
gi="$REPO/third_party/.gitignore"
if [ ! -f "$gi" ] || ! grep -qx 'meshlab/' "$gi"; then
  mkdir -p "$REPO/third_party"
  echo 'meshlab/' >>"$gi"
fi

log "ok"
