#!/usr/bin/env bash
# The web tests (called by scripts/test.sh):  bash web/test/run.sh BUILD_DIR POMAR_TOOL
#  1. builds the WebAssembly decoder (web/build.sh, in BUILD_DIR; it also vendors three.js
#     from npm into web/dist/ for the page);
#  2. encodes samples/bunny.ply three ways and a coloured mesh (web/test/coloured_mesh.py)
#     with the native tool and checks that the WASM decoder decodes them bit for bit like
#     the native one (colours too; and the per-corner texture coordinates and texture numbers
#     of the textured cube, samples/textured_sphere.obj and, when ../shared/data is there,
#     its textured bunny scan), and that damaged/truncated copies give messages
#     (web/test/wasm_decode_test.mjs, Node.js);
#  3. streams one of them from Debian's nginx and Apache through the client's own transport
#     (multipart/byteranges answers) and checks the meshes against the local file's
#     (web/test/real_servers.sh);
#  4. runs the viewer in headless Chromium (web/test/browser_test.py), screenshots compared
#     with docs/images/web_test/, a coloured Z-up model (web/test/coloured_mesh.py, encoded
#     here) drawn with its colours and stood up on Z, a textured cube
#     (web/test/textured_mesh.py: OBJ + MTL + two PNGs, encoded here) drawn with its
#     textures; then on an emulated phone with touch input (web/test/mobile_test.py).
# (Plus web/test/unit_test.mjs: request coalescing and the choice of levels for a view;
# web/test/detail_test.mjs: the detail measured per cluster on a flat + bumpy grid;
# web/test/texture_test.mjs: the texture coordinates and materials of the decoded meshes.)
# Each step is skipped with a message when emscripten, Node.js or Chromium is missing.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="$1"
TOOL="$2"
if ! command -v emcmake >/dev/null 2>&1 || ! command -v node >/dev/null 2>&1; then
  echo "web tests: SKIPPED: emscripten or node not installed (scripts/setup.sh installs them)"
  exit 0
fi
echo "web tests: building the WebAssembly decoder in $BUILD"
bash "$REPO/web/build.sh" "$BUILD"
samples="$BUILD/samples"
mkdir -p "$samples"
"$TOOL" encode "$REPO/samples/bunny.ply" "$samples/bunny.pomar" -q
"$TOOL" encode "$REPO/samples/bunny.ply" "$samples/bunny_c5.pomar" --cluster-ratio 0.05 -q
"$TOOL" encode "$REPO/samples/bunny.ply" "$samples/bunny_progressive.pomar" --progressive -q
python3 "$REPO/web/test/coloured_mesh.py" "$samples/coloured_zup.ply"
"$TOOL" encode "$samples/coloured_zup.ply" "$samples/coloured_zup.pomar" -q
python3 "$REPO/web/test/textured_mesh.py" "$samples/textured"
"$TOOL" encode "$samples/textured/textured.obj" "$samples/textured/textured.pomar" -q
"$TOOL" encode "$REPO/samples/textured_sphere.obj" "$samples/textured_sphere.pomar" -q
# A textured scan (charts that the positions map far from affinely), when the shared data is there.
scan="$REPO/../shared/data/meshlab_bunny10k_textured.obj"
textured_scan=()
if [ -f "$scan" ]; then
  "$TOOL" encode "$scan" "$samples/bunny_textured.pomar" -q
  textured_scan=("$samples/bunny_textured.pomar")
fi
node "$REPO/web/test/unit_test.mjs"
echo "web tests: texture coordinates and materials (node web/test/texture_test.mjs)"
node "$REPO/web/test/texture_test.mjs" "$samples/textured/textured.pomar"
echo "web tests: the measured detail of each cluster (node web/test/detail_test.mjs)"
node "$REPO/web/test/detail_test.mjs" "$TOOL"
# Stored errors and the spatial layout (sections CERR and BLKO), when the bench tool is built.
RA_BENCH="$(dirname "$TOOL")/../bench/pomar_ra_bench"
view_files=()
if [ -x "$RA_BENCH" ]; then
  "$RA_BENCH" encode "$REPO/samples/bunny.ply" "$samples/bunny_view.pomar" >/dev/null
  "$RA_BENCH" encode "$REPO/samples/bunny.ply" "$samples/bunny_view_c5.pomar" 0.05 >/dev/null
  view_files=("$samples/bunny_view.pomar")
fi
echo "web tests: WASM decode = native decode (node web/test/wasm_decode_test.mjs)"
node "$REPO/web/test/wasm_decode_test.mjs" "$TOOL" "$samples/bunny.pomar" "$samples/bunny_c5.pomar" \
  "$samples/bunny_progressive.pomar" "$samples/coloured_zup.pomar" "${view_files[@]}"
echo "web tests: WASM decode = native decode of textured files, every corner's (u, v) (node web/test/wasm_decode_test.mjs --textured)"
node "$REPO/web/test/wasm_decode_test.mjs" --textured "$TOOL" "$samples/textured/textured.pomar" \
  "$samples/textured_sphere.pomar" ${textured_scan[@]+"${textured_scan[@]}"}
if [ -x "$RA_BENCH" ]; then
  echo "web tests: view selection in WASM = native (node web/test/view_test.mjs)"
  "$TOOL" encode "$REPO/samples/bunny.ply" "$samples/bunny_edges.pomar" --no-stored-errors -q
  node "$REPO/web/test/view_test.mjs" "$RA_BENCH" "$samples/bunny_view.pomar" \
    "$samples/bunny_view_c5.pomar" "$samples/bunny.pomar" "$samples/bunny_edges.pomar"
else
  echo "web tests: view selection SKIPPED: no $RA_BENCH"
fi
bash "$REPO/web/test/real_servers.sh" "$samples/bunny_c5.pomar"
if ! command -v chromium >/dev/null 2>&1; then
  echo "web tests: browser test SKIPPED: chromium not installed"
  exit 0
fi
# A browser test: exit status 77 = skipped (Chromium or the build missing).
in_browser() {
  echo "web tests: $1 (web/test/$2)"
  local status=0
  python3 "$REPO/web/test/$2" "$samples/bunny_c5.pomar" "${@:3}" || status=$?
  if [ "$status" = 77 ]; then
    echo "web tests: $2 SKIPPED"
  elif [ "$status" != 0 ]; then
    exit "$status"
  fi
}
in_browser "the viewer in headless Chromium" browser_test.py --coloured "$samples/coloured_zup.pomar" \
  --textured "$samples/textured"
in_browser "the viewer on an emulated phone, touch input" mobile_test.py
echo "web tests: passed"
