#!/usr/bin/env bash
# Builds the WebAssembly decoder (web/dist/pomar_decoder.{mjs,wasm}) with emscripten, and
# vendors three.js (npm, pinned in web/package.json + package-lock.json) into web/dist/ for
# the viewer page (no CDN):
#   bash web/build.sh [BUILD_DIR]          (default: build-web/)
# The codec is compiled from its own CMake targets (web/CMakeLists.txt includes codec/).
# Debian's emscripten 3.1.6 runs its JavaScript tools with the system Node.js, which finds
# acorn only through NODE_PATH. Uses ccache when it is installed.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${1:-$REPO/build-web}"
if ! command -v emcmake >/dev/null 2>&1; then
  echo "web/build.sh: emscripten (emcmake) not found: apt-get install emscripten" >&2
  exit 77
fi
export NODE_PATH="${NODE_PATH:-/usr/share/nodejs}"
launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$REPO}"
fi
emcmake cmake -S "$REPO/web" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
cmake --build "$BUILD" -j "${JOBS:-2}"
echo "web/build.sh: built $REPO/web/dist/pomar_decoder.mjs + .wasm"
three="$REPO/web/node_modules/three"
pinned="$(sed -n 's/.*"three": "\(.*\)".*/\1/p' "$REPO/web/package.json")"
if [ ! -f "$three/build/three.module.js" ] || ! grep -q "\"version\": \"$pinned\"" "$three/package.json"; then
  if ! command -v npm >/dev/null 2>&1; then
    echo "web/build.sh: npm not found (apt-get install npm): the viewer page needs three.js" >&2
    exit 1
  fi
  (cd "$REPO/web" && npm ci --no-audit --no-fund --loglevel=error)
fi
cp "$three/build/three.module.js" "$three/build/three.core.js" "$REPO/web/dist/"
cp "$three/LICENSE" "$REPO/web/dist/three.LICENSE"
echo "web/build.sh: three.js $pinned in $REPO/web/dist/"
