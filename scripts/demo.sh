#!/usr/bin/env bash
# Demo: set up, build the pomar CLI (Release, Ninja, in build/), then round-trip the Stanford bunny:
#   samples/bunny.ply -> build/demo/bunny.pomar -> build/demo/bunny_decoded.ply, and verify it is lossless.
# When the MeshLab plugin target (io_pomar) is configured, it is built too and the project is installed
# into /usr (pomar -> /usr/bin, libio_pomar.so and libfilter_pomar.so ->
# /usr/lib/x86_64-linux-gnu/meshlab/plugins), so that
# meshlab and meshlabserver open .pomar; then meshlabserver converts build/demo/bunny.pomar to
# build/demo/bunny_meshlab.ply, which is verified the same way.
# Works from any directory. Installing into /usr needs root (or sudo).
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"

BUILD=build
DEMO="$BUILD/demo"
POMAR="$BUILD/codec/pomar"
BITS=12

bash scripts/setup.sh

echo "demo: configuring and building $POMAR (Release)"
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" --target pomar

# MeshLab plugin: build it and install the project into /usr (needs the io_pomar target, which CMake
# configures only when MeshLab, its headers and Qt are present; see io_plugin/CMakeLists.txt).
HAVE_PLUGIN=0
targets="$(cmake --build "$BUILD" --target help 2>/dev/null || true)" # Ninja: "io_pomar: phony"
if grep -Eq '^(\.\.\. )?io_pomar(:| |$)' <<<"$targets"; then
  HAVE_PLUGIN=1
  echo
  echo "demo: building the MeshLab plugins (io_pomar, filter_pomar) and installing into /usr"
  cmake --build "$BUILD" --target io_pomar filter_pomar
  SUDO=()
  if [ "$(id -u)" -ne 0 ] && command -v sudo >/dev/null 2>&1; then SUDO=(sudo); fi
  # The tool and the plugins only (CMake's default component): the "library" and "python"
  # components (cmake/PomarInstall.cmake, python/) are not built by this script.
  "${SUDO[@]}" cmake --install "$BUILD" --prefix /usr --component Unspecified
else
  echo
  echo "demo: no io_pomar target in $BUILD (MeshLab plugin not configured): skipping the plugin build, the install into /usr and the meshlabserver step"
fi

mkdir -p "$DEMO"
echo
echo "\$ pomar encode samples/bunny.ply $DEMO/bunny.pomar --bits $BITS"
"$POMAR" encode samples/bunny.ply "$DEMO/bunny.pomar" --bits "$BITS"
echo
echo "\$ pomar info $DEMO/bunny.pomar"
"$POMAR" info "$DEMO/bunny.pomar"
echo
echo "\$ pomar decode $DEMO/bunny.pomar $DEMO/bunny_decoded.ply"
"$POMAR" decode "$DEMO/bunny.pomar" "$DEMO/bunny_decoded.ply"
echo
echo "\$ pomar verify samples/bunny.ply $DEMO/bunny.pomar $DEMO/bunny_decoded.ply"
"$POMAR" verify samples/bunny.ply "$DEMO/bunny.pomar" "$DEMO/bunny_decoded.ply"
echo

if [ $HAVE_PLUGIN -eq 1 ]; then
  # meshlabserver exits 0 even when it could not open or save: check the output file instead.
  rm -f "$DEMO/bunny_meshlab.ply"
  echo "\$ xvfb-run -a meshlabserver -i $DEMO/bunny.pomar -o $DEMO/bunny_meshlab.ply"
  rc=0
  xvfb-run -a meshlabserver -i "$DEMO/bunny.pomar" -o "$DEMO/bunny_meshlab.ply" \
    >"$DEMO/meshlabserver.log" 2>&1 || rc=$?
  grep -E '^(Total .* io plugins|Current Plugins Dir)' "$DEMO/meshlabserver.log" || true
  if [ ! -s "$DEMO/bunny_meshlab.ply" ]; then
    cat "$DEMO/meshlabserver.log" >&2
    echo "demo: meshlabserver (exit $rc) did not write $DEMO/bunny_meshlab.ply" >&2
    exit 1
  fi
  echo "meshlabserver wrote $DEMO/bunny_meshlab.ply ($(stat -c %s "$DEMO/bunny_meshlab.ply") bytes; log in $DEMO/meshlabserver.log)"
  echo
  echo "\$ pomar verify samples/bunny.ply $DEMO/bunny.pomar $DEMO/bunny_meshlab.ply"
  "$POMAR" verify samples/bunny.ply "$DEMO/bunny.pomar" "$DEMO/bunny_meshlab.ply"
  echo
  echo "demo: meshlabserver opened bunny.pomar through the installed plugin; bunny_meshlab.ply matched too"
  echo
fi
echo "demo: bunny.ply -> bunny.pomar -> bunny_decoded.ply matched (lossless on the $BITS-bit grid)"
