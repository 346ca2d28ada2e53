#!/usr/bin/env bash
# Demo: set up, build the pomar CLI (Release, Ninja, in build/), then round-trip the Stanford bunny:
#   samples/bunny.ply -> build/demo/bunny.pomar -> build/demo/bunny_decoded.ply, and verify it is lossless.
# Works from any directory.
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
echo "demo: bunny.ply -> bunny.pomar -> bunny_decoded.ply matched (lossless on the $BITS-bit grid)"
