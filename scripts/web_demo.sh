#!/usr/bin/env bash
# The web viewer demo: builds the pomar tool (build/) and the WebAssembly decoder (build-web/),
# encodes samples/bunny.ply into build-web/demo/, serves the repository on 127.0.0.1 with
# web/serve.py (HTTP Range support) and prints the URL to open. Ctrl-C stops the server.
#   bash scripts/web_demo.sh [PORT]        (default 8000)
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"
PORT="${1:-8000}"
bash scripts/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --target pomar
bash web/build.sh "$REPO/build-web"
mkdir -p build-web/demo
build/codec/pomar encode samples/bunny.ply build-web/demo/bunny.pomar -q
echo "web_demo: open http://127.0.0.1:$PORT/web/index.html?file=/build-web/demo/bunny.pomar"
exec python3 web/serve.py --root "$REPO" --port "$PORT" --quiet
