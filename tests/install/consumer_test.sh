#!/usr/bin/env bash
# The installed package as a library user meets it: installs the "library" component of
# BUILD into a fresh prefix, then builds the README's example programs (examples/) against
# it as a separate CMake project (find_package) and with pkg-config, and runs them on
# SAMPLE. Also: every public header compiles on its own from the prefix (no src/ include),
# and the README quotes the example files verbatim. With PYTHON (the interpreter the
# module was built for; empty if it was not built): installs the "python" component into
# the same prefix and runs the README's Python session (examples/session.py) from there.
#   consumer_test.sh BUILD_DIR SOURCE_DIR CXX VCGLIB_DIR SAMPLE.ply [PYTHON]
set -euo pipefail
BUILD="$1" SRC="$2" CXX="$3" VCGLIB="$4" SAMPLE="$5" PYTHON="${6:-}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"

fail() { echo "consumer_test: FAILED: $*" >&2; exit 1; }

echo "== README quotes examples/ verbatim"
python3 - "$SRC" <<'PY'
import pathlib, sys
src = pathlib.Path(sys.argv[1])
readme = (src / "README.md").read_text()
for example in ("encode_decode.cpp", "selective_decode.cpp", "session.py", "trimesh_convert.py"):
    code = (src / "examples" / example).read_text()
    # The README shows a C++ program from its first #include on.
    body = code[code.index("#include"):] if example.endswith(".cpp") else code
    if body not in readme:
        sys.exit(f"README.md does not quote examples/{example} (from its first #include) verbatim")
PY

echo "== cmake --install --component library --prefix $prefix"
cmake --install "$BUILD" --component library --prefix "$prefix" >/dev/null
[ ! -e "$prefix/bin/pomar" ] || fail "the library component installed the tool"
pc="$(find "$prefix" -name pomar.pc)"
[ -n "$pc" ] || fail "no pomar.pc installed"

echo "== each public header compiles alone against the prefix"
for h in "$prefix"/include/pomar/*.h; do
  name="pomar/$(basename "$h")"
  extra=()
  [ "$name" = pomar/vcg_adapter.h ] && extra=(-isystem "$VCGLIB" -isystem /usr/include/eigen3)
  printf '#include <%s>\n#include <%s>\n' "$name" "$name" >"$work/one.cpp"
  "$CXX" -std=c++17 -Wall -Wextra -Werror -fsyntax-only -I"$prefix/include" "${extra[@]}" \
    "$work/one.cpp" || fail "$name does not compile on its own"
done

run_examples() { # DIR LABEL
  "$1/encode_decode" "$SAMPLE" "$work/$2.pomar" || fail "$2: encode_decode"
  "$1/selective_decode" "$work/$2.pomar" || fail "$2: selective_decode"
}

echo "== find_package(pomar CONFIG)"
cmake -S "$SRC/examples" -B "$work/cmake" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/cmake" >/dev/null
run_examples "$work/cmake" cmake

echo "== pkg-config pomar"
export PKG_CONFIG_PATH="$(dirname "$pc")"
flags=($(pkg-config --cflags --libs pomar))
mkdir "$work/pc"
for e in encode_decode selective_decode; do
  "$CXX" -std=c++17 -O1 "$SRC/examples/$e.cpp" -o "$work/pc/$e" "${flags[@]}"
done
# A shared build's libraries are found through the library path (no RPATH from pkg-config).
LD_LIBRARY_PATH="$(dirname "$(dirname "$pc")"):${LD_LIBRARY_PATH:-}" run_examples "$work/pc" pkgconfig

if [ -n "$PYTHON" ] && ! "$PYTHON" -c 'import numpy' 2>/dev/null; then
  echo "== the Python session: skipped (no numpy for $PYTHON: python3-numpy)"
elif [ -n "$PYTHON" ]; then
  echo "== the Python session (examples/session.py) from cmake --install --component python"
  cmake --install "$BUILD" --component python --prefix "$prefix" >/dev/null
  init="$(find "$prefix" -path '*/pomar/__init__.py')"
  [ -n "$init" ] || fail "no pomar/__init__.py installed"
  (cd "$SRC" && PYTHONPATH="$(dirname "$(dirname "$init")")" "$PYTHON" -c '
import runpy, pomar
assert pomar.__file__.startswith("'"$prefix"'"), pomar.__file__
runpy.run_path("examples/session.py")') || fail "examples/session.py"
fi
echo "consumer_test: ok"
