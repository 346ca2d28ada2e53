#!/usr/bin/env bash
# Encode wall time and peak memory of two pomar tools (before / after) and Draco, interleaved
# so that all three see the same load: per mesh and thread count, RUNS rounds of (before,
# after, draco_encoder -qp 12 -cl 7); prints the medians (elapsed s, user CPU s, peak MB).
#
#   bash bench/encode_timing.sh BEFORE_POMAR AFTER_POMAR MESH... [-- RUNS]
#
# Threads: 1 and 2 (--threads). Draco is single-threaded: its figures are repeated.
set -u
BEFORE=${1:?pomar tool before}
AFTER=${2:?pomar tool after}
shift 2
RUNS=3
meshes=()
while [ $# -gt 0 ]; do
  if [ "$1" = -- ]; then
    RUNS=${2:?runs}
    break
  fi
  meshes+=("$1")
  shift
done
W=$(mktemp -d /tmp/encode_timing.XXXXXX)
trap 'rm -rf "$W"' EXIT

measure() { # label command... : appends "elapsed user maxrss_kb" to $W/label.times
  local label=$1
  shift
  /usr/bin/time -f "%e %U %M" -o "$W/t" "$@" >/dev/null 2>&1 || echo "FAILED: $*" >&2
  tail -1 "$W/t" >>"$W/$label.times"
}

median() { # file column
  sort -n -k"$2" "$1" | awk -v c="$2" '{v[NR] = $c} END {print v[int((NR + 1) / 2)]}'
}

printf '| mesh | threads | before s (user) | after s (user) | Draco s (user) | before / Draco | after / Draco | before MB | after MB | Draco MB |\n'
printf '|:--|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n'
for m in "${meshes[@]}"; do
  for t in 1 2; do
    rm -f "$W"/*.times
    for _ in $(seq "$RUNS"); do
      measure before "$BEFORE" encode -q --threads "$t" "$m" "$W/before.pomar"
      measure after "$AFTER" encode -q --threads "$t" "$m" "$W/after.pomar"
      measure draco draco_encoder -qp 12 -cl 7 -i "$m" -o "$W/out.drc"
    done
    cmp -s "$W/before.pomar" "$W/after.pomar" || echo "NOTE: the two tools' files differ on $m" >&2
    row=()
    for k in before after draco; do
      row+=("$(median "$W/$k.times" 1)" "$(median "$W/$k.times" 2)" "$(median "$W/$k.times" 3)")
    done
    awk -v m="$(basename "$m")" -v t="$t" -v r="${row[*]}" 'BEGIN {
      split(r, x, " ");
      printf "| %s | %s | %.2f (%.2f) | %.2f (%.2f) | %.2f (%.2f) | %.2f | %.2f | %.0f | %.0f | %.0f |\n",
        m, t, x[1], x[2], x[4], x[5], x[7], x[8], x[1] / x[7], x[4] / x[7], x[3] / 1024, x[6] / 1024, x[9] / 1024
    }'
  done
done
