#!/usr/bin/env bash
# Tests of bench/pomar_rd (docs/rate_distortion.md) on samples/bunny.ply; no ../shared data needed.
#   test_rd.sh POMAR_RD POMAR_CLI POMAR_GEN_MESH SAMPLES_DIR
# 1. the full decode's error is the quantization error: Hausdorff <= sqrt(3)/2 * cell / diag
#    (a vertex moves at most half a cell per axis; surface points are convex combinations);
# 2. errors fall as levels are added (RMS may rise by at most 10% from one level to the
#    next: sampling noise; overall at least 100x from level 0 to the full mesh);
# 3. a .pomar of another mesh is rejected with a clear message and a non-zero exit.
set -u
# About 7 s of CPU, most of it pomar_rd's distances; bounded by CPU time (ulimit -t), which
# the machine's load does not stretch; ctest's TIMEOUT is a backstop for a hang.
ulimit -t 120
RD=$1 CLI=$2 GEN=$3 SAMPLES=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok: $*"; }
bad() { echo "FAIL: $*"; fail=1; }

"$RD" "$SAMPLES/bunny.ply" --samples 5000 --no-draco --csv "$tmp/rd.csv" --svg "$tmp/rd.svg" \
  >"$tmp/out.txt" 2>"$tmp/err.txt" || { cat "$tmp/out.txt" "$tmp/err.txt"; bad "pomar_rd failed"; exit 1; }
[ -s "$tmp/rd.svg" ] && grep -q '</svg>' "$tmp/rd.svg" && ok "svg written" || bad "no svg"
bound=$(sed -n 's/^quantization bound (sqrt(3)\/2 \* cell \/ diag): \([0-9.e+-]*\).*/\1/p' "$tmp/out.txt")
[ -n "$bound" ] || bad "no quantization bound printed"

python3 - "$tmp/rd.csv" "$bound" <<'PY' || fail=1
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
bound = float(sys.argv[2])
curve = [r for r in rows if r["kind"] in ("global", "clustered")]
curve.sort(key=lambda r: int(r["level"]))
full = curve[-1]
err = 0
h = float(full["hausdorff_rel"])
if h <= bound * 1.001:
    print(f"ok: full decode Hausdorff {h:.4e} <= quantization bound {bound:.4e}")
else:
    print(f"FAIL: full decode Hausdorff {h:.4e} > quantization bound {bound:.4e}"); err = 1
rms = [float(r["rms_rel"]) for r in curve]
bpv = [float(r["bpv"]) for r in curve]
for a, b, r in zip(rms, rms[1:], curve[1:]):
    if b > a * 1.10:
        print(f"FAIL: RMS rises at {r['state']}: {a:.4e} -> {b:.4e}"); err = 1
if not all(y >= x for x, y in zip(bpv, bpv[1:])):
    print("FAIL: bits per vertex not increasing with the level"); err = 1
if rms[-1] * 100 > rms[0]:
    print(f"FAIL: RMS falls too little: {rms[0]:.4e} -> {rms[-1]:.4e}"); err = 1
if not err:
    print(f"ok: RMS falls over {len(rms)} levels: {rms[0]:.3e} -> {rms[-1]:.3e}")
states = {r["state"] for r in rows if r["kind"] == "state"}
if states != {"base clustered", "cluster 0 finest", "all refined"}:
    print(f"FAIL: clustered states {states}"); err = 1
sys.exit(err)
PY

# A .pomar of another mesh (a generated torus) must be rejected.
"$GEN" torus 2000 "$tmp/torus.ply" >/dev/null && "$CLI" encode "$tmp/torus.ply" "$tmp/torus.pomar" >/dev/null \
  || bad "cannot make torus.pomar"
"$RD" "$SAMPLES/bunny.ply" "$tmp/torus.pomar" --no-draco >"$tmp/out2.txt" 2>"$tmp/err2.txt"
rc=$?
if [ $rc -ne 0 ] && grep -q "does not encode" "$tmp/err2.txt"; then
  ok "another mesh's .pomar rejected (exit $rc): $(cat "$tmp/err2.txt")"
else
  bad "another mesh's .pomar not rejected (exit $rc): $(cat "$tmp/err2.txt")"
fi
# Same vertex and face counts, another bounding box: the torus moved by half its size.
python3 - "$tmp/torus.ply" "$tmp/moved.ply" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
header = data[:end].decode()
nv = int(header.split("element vertex ")[1].split()[0])
xyz = list(struct.unpack_from("<%df" % (3 * nv), data, end))
xs = xyz[0::3]
shift = 0.5 * (max(xs) - min(xs))
for i in range(0, len(xyz), 3):
    xyz[i] += shift
open(sys.argv[2], "wb").write(data[:end] + struct.pack("<%df" % (3 * nv), *xyz) + data[end + 12 * nv:])
PY
"$RD" "$tmp/moved.ply" "$tmp/torus.pomar" --no-draco >"$tmp/out3.txt" 2>"$tmp/err3.txt"
rc=$?
if [ $rc -ne 0 ] && grep -q "does not encode.*grid" "$tmp/err3.txt"; then
  ok "moved mesh rejected (exit $rc): $(cat "$tmp/err3.txt")"
else
  bad "moved mesh not rejected (exit $rc): $(cat "$tmp/err3.txt")"
fi
exit $fail
