#!/usr/bin/env bash
# End-to-end test of the MeshLab filter plugin libfilter_pomar.so through meshlabserver 2020.09:
# runs every samples/*.mlx script on .pomar files and checks the results.
#
#   bash tests/meshlab_plugin/meshlabserver_test.sh IO_PLUGIN.so FILTER_PLUGIN.so POMAR_CLI \
#        SAMPLES_DIR WORK_DIR [MESHLAB_LIBDIR]
#
# Registered in ctest as "meshlab_plugin_meshlabserver" (tests/meshlab_plugin/CMakeLists.txt).
# Builds a private MeshLab tree in WORK_DIR (recipe /work/shared/docs/meshlab-plugins.md, 5b: a
# *copy* of meshlabserver in tree/bin, symlinks to libmeshlab-common.so, the stock plugins
# libio_base.so (PLY), libfilter_select.so (Select Faces from Vertices) and libfilter_func.so
# (Conditional Vertex Selection), and ours). Every call runs under `xvfb-run -a` with HOME in
# WORK_DIR. meshlabserver exits 0 even when a save fails, so the checks look at the files. The
# tree, the meshlabserver runs and the check helpers come from tests/support/meshlab_tree.sh.
#
# The scripts in samples/ hold the levels of samples/bunny.ply encoded with the default options;
# the test reads the real ones from `pomar info --json` (global_levels, level_count) and runs
# copies with those values. Every samples/*.mlx must be run here: an unknown one fails the test.
# Exits 77 (ctest SKIP_RETURN_CODE) when meshlabserver, xvfb-run, python3, MeshLab's library or a
# stock plugin is missing. The first failing check prints what failed and exits 1.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=../support/meshlab_tree.sh
. "$(dirname "${BASH_SOURCE[0]}")/../support/meshlab_tree.sh"

if [ $# -lt 5 ] || [ $# -gt 6 ]; then
  echo "usage: $0 IO_PLUGIN.so FILTER_PLUGIN.so POMAR_CLI SAMPLES_DIR WORK_DIR [MESHLAB_LIBDIR]" >&2
  exit 2
fi
IO_PLUGIN="$(abspath "$1")"
FILTER_PLUGIN="$(abspath "$2")"
mlserver_args "${@:3}"   # POMAR SAMPLES WORK MLLIB
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
PLYTOOL="$HERE/plytool.py"
STOCK=(libio_base.so libfilter_select.so libfilter_func.so)

skip_without_server
skip_without python3 "python3 is not installed"
skip_without_meshlab_lib "$MLLIB" "${STOCK[@]}"
for f in "$IO_PLUGIN" "$FILTER_PLUGIN"; do
  [ -f "$f" ] || { echo "FAIL: plugin not found: $f" >&2; exit 1; }
done
[ -x "$POMAR" ] || { echo "FAIL: pomar executable not found: $POMAR" >&2; exit 1; }
BUNNY="$SAMPLES/bunny.ply"
[ -f "$BUNNY" ] || { echo "FAIL: $BUNNY missing" >&2; exit 1; }

# ---- the private MeshLab tree (tests/support/meshlab_tree.sh), checks ----------------------------------

mlserver_prepare "$WORK" "$MLLIB" "${STOCK[@]}"
mltree_link_as "$TREE" "$IO_PLUGIN" libio_pomar.so
mltree_link_as "$TREE" "$FILTER_PLUGIN" libfilter_pomar.so
rm -rf "$WORK/scripts"
mkdir -p "$WORK/scripts"

# fail_excerpt: what fail shows of the output: the last 40 lines, without the filters' progress lines.
fail_excerpt() { grep -v '^POMAR: [a-z]*ing' | sed 's/^/    /' | tail -40; }
log_line() { printf '%s\n' "$OUT" | grep -m1 "^LOG: .*$1" | sed 's/^LOG: [0-9]* /    /' || true; }
# counts FILE.ply: sets VN and FN.
counts() {
  run python3 "$PLYTOOL" count "$1"
  expect_rc 0
  read -r VN FN <<<"$OUT"
}
# manifold FILE.ply: `pomar encode` refuses non-manifold or inconsistently oriented meshes.
manifold() {
  run "$POMAR" encode -q "$1" "$WORK/out/manifold_check.pomar"
  [ "$RC" -eq 0 ] || fail "$(basename "$1") is not a valid manifold mesh for pomar encode"
  pass
  rm -f "$WORK/out/manifold_check.pomar"
}

# ---- every samples/*.mlx is covered, and writes every parameter of its filters ----------------------

KNOWN_SCRIPTS="refine_region full_resolution coarsen_and_show show_clusters"
section "samples/*.mlx: all known to this test, every filter parameter written"
for f in "$SAMPLES"/*.mlx; do
  name="$(basename "$f" .mlx)"
  case " $KNOWN_SCRIPTS " in *" $name "*) pass ;; *) fail "$f is not run by this test: add it" ;; esac
done
for name in $KNOWN_SCRIPTS; do expect_file "$SAMPLES/$name.mlx"; done
# The parameters each filter declares (Debian's meshlabserver asserts unless all are given).
run python3 - "$SAMPLES"/*.mlx <<'EOF'
import sys
import xml.etree.ElementTree as ET
declared = {
    'POMAR: Refine Selected Clusters': {'TargetLevel': 'RichInt'},
    'POMAR: Coarsen Selected Clusters': {'TargetLevel': 'RichInt'},
    'POMAR: Set Level of Detail': {'Level': 'RichInt'},
    'POMAR: Show Clusters': {},
    'POMAR: Show Levels': {},
    'Conditional Vertex Selection': {'condSelect': 'RichString'},
    'Select Faces from Vertices': {'Inclusive': 'RichBool'},
}
bad = 0
for path in sys.argv[1:]:
    root = ET.parse(path).getroot()
    assert root.tag == 'FilterScript', path
    for f in root.findall('filter'):
        name = f.get('name')
        if name not in declared:
            print(f'{path}: filter "{name}" unknown to this test'); bad += 1; continue
        given = {p.get('name'): p.get('type') for p in f.findall('Param')}
        if given != declared[name]:
            print(f'{path}: "{name}" has parameters {given}, expected {declared[name]}'); bad += 1
        for p in f.findall('Param'):
            if p.get('type') == 'RichBool' and p.get('value') not in ('true', 'false'):
                print(f'{path}: RichBool {p.get("name")} must be true or false'); bad += 1
sys.exit(1 if bad else 0)
EOF
expect_rc 0

# ---- inputs --------------------------------------------------------------------------------------------

section "encode samples/bunny.ply (clustered and pure progressive) and decode the reference"
run "$POMAR" encode -q "$BUNNY" "$OUTDIR/bunny.pomar"
expect_rc 0
run "$POMAR" encode -q --progressive "$BUNNY" "$OUTDIR/prog.pomar"
expect_rc 0
run "$POMAR" decode -q "$OUTDIR/bunny.pomar" "$OUTDIR/full.ply"
expect_rc 0
run "$POMAR" info --json "$OUTDIR/bunny.pomar"
expect_rc 0
read -r BASE FINEST CLUSTERS <<<"$(printf '%s' "$OUT" |
  python3 -c 'import json,sys; j=json.load(sys.stdin); print(j["global_levels"], j["level_count"], j["clusters"])')"
{ [ "$BASE" -gt 0 ] && [ "$FINEST" -gt "$BASE" ] && [ "$CLUSTERS" -gt 0 ]; } ||
  fail "unexpected levels from pomar info --json: base $BASE, finest $FINEST, clusters $CLUSTERS"
pass
counts "$OUTDIR/full.ply"
FULL_VN=$VN
echo "    bunny.pomar: base clustered level $BASE, finest level $FINEST, $CLUSTERS clusters, $FULL_VN vertices"

# script NAME: a copy of samples/NAME.mlx with this file's levels (the samples hold bunny's with
# the default options: base clustered level 16, finest 32).
script() {
  local out="$WORK/scripts/$1.mlx"
  sed -e "s/value=\"16\" name=\"Level\"/value=\"$BASE\" name=\"Level\"/" \
      -e "s/value=\"16\" name=\"TargetLevel\"/value=\"$BASE\" name=\"TargetLevel\"/" \
      -e "s/value=\"32\" name=\"TargetLevel\"/value=\"$FINEST\" name=\"TargetLevel\"/" \
      "$SAMPLES/$1.mlx" >"$out"
  if [ "$BASE" != 16 ] || [ "$FINEST" != 32 ]; then
    echo "    note: $1.mlx run with levels $BASE/$FINEST instead of the sample's 16/32" >&2
  fi
  echo "$out"
}

# ---- (a) refine a region of the base clustered mesh ------------------------------------------------------

section "refine_region.mlx: base clustered mesh, select y > 0.15, refine those clusters to the finest level"
ml -i bunny.pomar -s "$(script refine_region)" -o region.ply
expect_rc 0
expect_output "Current Plugins Dir is: $PLUGDIR"
expect_output "POMAR: set level of detail $BASE (base clustered)"
expect_output "POMAR: refined "
# The refinement starts from the decoder state the previous filter left: no rebuild.
expect_output "incremental, on the cached decoder state"
expect_no_output "Problem with filter"
expect_file "$OUTDIR/region.ply"
log_line "POMAR: refined"
counts "$OUTDIR/region.ply"
echo "    region.ply: $VN vertices, $FN faces (full resolution: $FULL_VN)"
[ "$VN" -lt "$FULL_VN" ] || fail "region.ply has $VN vertices, not fewer than the full mesh's $FULL_VN"
pass
[ "$VN" -gt "$CLUSTERS" ] || fail "region.ply has $VN vertices: nothing was refined"
pass

section "region.ply is manifold and holds every full-resolution vertex with y > 0.15"
manifold "$OUTDIR/region.ply"
run python3 "$PLYTOOL" contains "$OUTDIR/region.ply" "$OUTDIR/full.ply" y 0.15
[ "$RC" -eq 0 ] || fail "vertices of the selected region are missing at full resolution"
pass
printf '    %s\n' "$OUT"

# ---- (b) everything at the finest level = the lossless decode -------------------------------------------

section "full_resolution.mlx on bunny.pomar: equals the lossless decode"
# meshlabserver opens the .pomar at full resolution already, so also go there from a coarse state:
# refine_region.mlx first, then full_resolution.mlx (several -s run in order on one layer).
ml -i bunny.pomar -s "$(script refine_region)" -s "$(script full_resolution)" -o everything.ply
expect_rc 0
expect_output "POMAR: set level of detail $FINEST (full resolution)"
expect_file "$OUTDIR/everything.ply"
run "$POMAR" verify "$BUNNY" "$OUTDIR/bunny.pomar" "$OUTDIR/everything.ply"
expect_rc 0
expect_output "OK"

section "full_resolution.mlx right after opening (decoder starts at the base clustered mesh)"
ml -i bunny.pomar -s "$(script full_resolution)" -o full_direct.ply
expect_rc 0
run "$POMAR" verify "$BUNNY" "$OUTDIR/bunny.pomar" "$OUTDIR/full_direct.ply"
expect_rc 0

section "full_resolution.mlx on a pure progressive file"
ml -i prog.pomar -s "$(script full_resolution)" -o prog_full.ply
expect_rc 0
run "$POMAR" verify "$BUNNY" "$OUTDIR/prog.pomar" "$OUTDIR/prog_full.ply"
expect_rc 0

# ---- coarsen + show levels; show clusters ---------------------------------------------------------------

section "coarsen_and_show.mlx: coarsen the top at full resolution, colour the level map"
ml -i bunny.pomar -s "$(script coarsen_and_show)" -o levels.ply -m vc
expect_rc 0
expect_output "POMAR: coarsened "
# Nothing cached for a freshly opened layer: the state comes from its attributes, and it is
# exactly what the IO plugin decoded.
expect_output "decoder state rebuilt from the layer's attributes"
expect_no_output "differs from what the file decodes"
expect_output "POMAR: levels shown"
expect_file "$OUTDIR/levels.ply"
log_line "POMAR: coarsened"
counts "$OUTDIR/levels.ply"
[ "$VN" -lt "$FULL_VN" ] || fail "levels.ply has $VN vertices, not fewer than the full mesh's $FULL_VN"
pass
manifold "$OUTDIR/levels.ply"
run python3 "$PLYTOOL" colors "$OUTDIR/levels.ply"
expect_rc 0
read -r COLOURS _ RED <<<"$OUT"   # colours, blue (unused), red
echo "    levels.ply: $COLOURS colours, $RED red (finest level) vertices of $VN"
{ [ "$COLOURS" -gt 1 ] && [ "$RED" -gt 0 ] && [ "$RED" -lt "$VN" ]; } ||
  fail "expected several level colours with some, not all, vertices red: $COLOURS colours, $RED red"
pass

section "show_clusters.mlx: one colour per cluster"
ml -i bunny.pomar -s "$(script show_clusters)" -o clusters.ply -m vc
expect_rc 0
expect_output "POMAR: coloured $CLUSTERS clusters"
run python3 "$PLYTOOL" colors "$OUTDIR/clusters.ply"
expect_rc 0
read -r COLOURS _ RED <<<"$OUT"   # colours, blue (unused), red
echo "    clusters.ply: $COLOURS distinct colours for $CLUSTERS clusters"
{ [ "$((COLOURS * 100))" -ge "$((CLUSTERS * 95))" ] && [ "$COLOURS" -le "$CLUSTERS" ]; } ||
  fail "$COLOURS distinct colours for $CLUSTERS clusters"
pass

# ---- refusals -------------------------------------------------------------------------------------------

section "a layer that is not from a .pomar file is refused"
ml -i "$BUNNY" -s "$(script full_resolution)" -o refused.ply
expect_nonzero
expect_output "works only on a layer opened from a .pomar file"
expect_output "Problem with filter: POMAR: Set Level of Detail"
expect_no_file "$OUTDIR/refused.ply"

section "refining a pure progressive file is refused (no clusters)"
ml -i prog.pomar -s "$(script refine_region)" -o refused.ply
expect_nonzero
expect_output "is a pure progressive file: it has no clusters to refine"
expect_no_file "$OUTDIR/refused.ply"

section "show_clusters.mlx on a pure progressive file is refused"
ml -i prog.pomar -s "$(script show_clusters)" -o refused.ply
expect_nonzero
expect_output "has no cluster"
expect_no_file "$OUTDIR/refused.ply"

echo "PASS: $CHECKS checks"
