#!/usr/bin/env python3
"""Measures README.md's results tables and rewrites them in place.

    python3 bench/readme_results.py                # sizes and times (a quiet machine: minutes)
    python3 bench/readme_results.py --sizes-only   # file sizes against Draco (deterministic)
    python3 bench/readme_results.py --times-only   # whole-command times and peaks against Draco
    python3 bench/readme_results.py --quick --sizes-only --readme COPY.md   # samples/bunny only

Each table sits between marker comments in README.md (`<!-- readme_results:sizes begin -->` ...
`<!-- readme_results:sizes end -->`, the same with `times`) and is written with the date, the
machine (nproc, CPU model), the git commit, Draco's version and the command line that made it.
Sizes: 12-bit grid, bits per vertex = 8 x file bytes / vertices (the ones faces use), positions
and triangles only on both sides: pomar `--drop all`, `--progressive` and the default
random-access file, `draco_encoder -qp 12 -cl 7 --skip NORMAL --skip TEX_COORD --skip GENERIC`;
every pomar file is checked with `pomar verify`. Times: `--runs` interleaved rounds (pomar
encode `--drop all`, Draco encode, pomar decode, Draco decode, ...), whole commands under GNU
time, medians, reported as pomar / Draco of the same rounds. Needs a built tree (`--build`, default build/),
draco_encoder and draco_decoder on PATH, GNU time and xz. Exit status 77 when Draco is absent.
"""

import argparse
import datetime
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench  # noqa: E402  (measure, draco_input, materialize, machine facts)

REPO = bench.REPO
SKIP = 77  # ctest's SKIP_RETURN_CODE
# (label, file, source): source "samples" (in samples/), "data" (in --data) or "generated"
# (a noisy sphere of about that many vertices from pomar_gen_mesh).
MESHES = [
    ("bunny (sample)", "bunny.ply", "samples"),
    ("horse", "horse.ply", "data"),
    ("armadillo 50k", "armadillo_50k.obj", "data"),
    ("fertility 23k (genus 4)", "fertility_23k.off", "data"),
    ("rocker arm", "rocker_arm.off", "data"),
    ("bimba 9k", "bimba_9k.off", "data"),
    ("dragon (151 components)", "dragon.ply.xz", "data"),
    ("noisy sphere (generated)", 134_000, "generated"),
    ("noisy sphere (generated)", 1_000_000, "generated"),
]


def log(msg):
    print("readme_results: " + msg, file=sys.stderr, flush=True)


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise RuntimeError("%s failed (exit %d): %s" % (os.path.basename(cmd[0]), r.returncode,
                                                         bench.first_error_line(r.stderr)))
    return r.stdout


def pomar_info(tools, path):
    return json.loads(run([tools["pomar"], "info", path, "--json"]))


def draco_args(tools, src, drc, bits):
    return [tools["draco_encoder"], "-i", src, "-o", drc, "-qp", str(bits), "-cl", "7",
            "--skip", "NORMAL", "--skip", "TEX_COORD", "--skip", "GENERIC"]


def sizes_row(label, path, tools, work, bits):
    """File sizes of one mesh: pomar progressive and random access, Draco; pomar verified."""
    prog = os.path.join(work, "progressive.pomar")
    ra = os.path.join(work, "ra.pomar")
    enc = [tools["pomar"], "encode", path]
    run(enc + [prog, "--bits", str(bits), "--drop", "all", "--progressive", "-q"])
    run(enc + [ra, "--bits", str(bits), "--drop", "all", "-q"])
    p, a = pomar_info(tools, prog), pomar_info(tools, ra)
    lossless = all(subprocess.run([tools["pomar"], "verify", path, f, "--drop", "all"],
                                  capture_output=True).returncode == 0 for f in (prog, ra))
    nv = int(a["vertices"])
    drc = os.path.join(work, "out.drc")
    run(draco_args(tools, bench.draco_input(path, work), drc, bits))
    ddec = os.path.join(work, "draco.ply")
    run([tools["draco_decoder"], "-i", drc, "-o", ddec])
    draco_bytes = os.path.getsize(drc)
    return {
        "mesh": label, "vertices": nv, "input_vertices": int(a["input_vertices"]),
        "lossless": lossless,
        "prog_bpv": float(p["bpv"]), "conn_bpv": float(p["connectivity_bpv"]),
        "geom_bpv": float(p["geometry_bpv"]), "ra_bpv": float(a["bpv"]),
        "ra_bytes": int(a["total_bytes"]), "prog_bytes": int(p["total_bytes"]),
        "draco_bpv": 8.0 * draco_bytes / nv, "draco_bytes": draco_bytes,
        "draco_vertices": bench.ply_vertex_count(ddec),
    }


def times_row(label, path, tools, work, bits, runs):
    """Whole-command times and peaks of one mesh, pomar and Draco in interleaved rounds."""
    pf, pd = os.path.join(work, "t.pomar"), os.path.join(work, "t_decoded.ply")
    df, dd = os.path.join(work, "t.drc"), os.path.join(work, "t_draco.ply")
    src = bench.draco_input(path, work)
    cmds = {
        "enc": ([tools["pomar"], "encode", path, pf, "--bits", str(bits), "--drop", "all", "-q"],
                pf),
        "denc": (draco_args(tools, src, df, bits), df),
        "dec": ([tools["pomar"], "decode", pf, pd, "-q"], pd),
        "ddec": ([tools["draco_decoder"], "-i", df, "-o", dd], dd),
    }
    run(cmds["enc"][0])  # warm-up (and the validity check); not counted
    seconds = {k: [] for k in cmds}
    peaks = {k: [] for k in cmds}
    for _ in range(runs):
        for key in ("enc", "denc", "dec", "ddec"):
            cmd, out = cmds[key]
            if os.path.exists(out):
                os.remove(out)
            r = bench.measure(cmd, work)
            if r.rc != 0 or not os.path.exists(out):
                raise RuntimeError("%s failed (exit %d): %s" % (
                    os.path.basename(cmd[0]), r.rc, bench.first_error_line(r.stderr)))
            seconds[key].append(r.seconds)
            if r.peak_mb is not None:
                peaks[key].append(r.peak_mb)
    med = {k: statistics.median(v) for k, v in seconds.items()}
    peak = {k: (max(v) if v else None) for k, v in peaks.items()}
    return {"mesh": label, "vertices": int(pomar_info(tools, pf)["vertices"]), "runs": runs,
            "enc_ratio": med["enc"] / med["denc"], "dec_ratio": med["dec"] / med["ddec"],
            "enc_mb": peak["enc"], "denc_mb": peak["denc"], "dec_mb": peak["dec"],
            "ddec_mb": peak["ddec"]}


def header_lines(command, bits, what):
    machine, date = bench.machine_lines(None)
    return ["%s, %d-bit grid: `%s`" % (what, bits, command),
            "(%s; %s)." % (machine[2:].replace("Machine: ", "machine: "),
                           date[2:].replace("Date: ", "measured "))]


def sizes_block(rows, notes, command, bits):
    lines = header_lines(command, bits, "Sizes") + [""]
    lines.append("Positions and triangles on both sides (pomar `--drop all`; Draco `--skip NORMAL "
                 "--skip TEX_COORD --skip GENERIC`); bits per vertex = 8 × file bytes / "
                 "vertices.")
    lines.append("")
    lines.append("| mesh | vertices | progressive bpv (conn + geom) | **random access bpv** "
                 "(default, 1% clusters) | overhead | Draco bpv | size / Draco |")
    lines.append("|:--|--:|--:|--:|--:|--:|--:|")
    starred = []
    for r in rows:
        star = ""
        if r["draco_vertices"] is not None and r["draco_vertices"] != r["input_vertices"]:
            star = "*"
            starred.append("%s of the %s's %s" % (format(r["draco_vertices"], ","),
                                                  r["mesh"].split(" (")[0],
                                                  format(r["input_vertices"], ",")))
        lines.append("| %s | %s | %.2f (%.2f + %.2f) | **%.2f** | %+.1f%% | %.2f%s | %.2f |" % (
            r["mesh"], format(r["vertices"], ","), r["prog_bpv"], r["conn_bpv"], r["geom_bpv"],
            r["ra_bpv"], 100.0 * (r["ra_bytes"] / r["prog_bytes"] - 1.0), r["draco_bpv"], star,
            r["ra_bytes"] / r["draco_bytes"]))
    lines.append("")
    bad = [r["mesh"] for r in rows if not r["lossless"]]
    if bad:
        lines.append("**`pomar verify` fails on: %s.**" % ", ".join(bad))
    else:
        lines.append("Every pomar file above passes `pomar verify --drop all` (lossless).")
    if starred:
        lines.append("\\*Draco decodes %s vertices (it drops vertices no face uses, merges "
                     "coincident ones and drops zero-area faces): it is not lossless there; "
                     "pomar gives back every input vertex, and its bpv divides by the "
                     "vertices faces use, as Draco's." % " and ".join(starred))
    lines += ["- " + n for n in notes]
    return lines


def times_block(rows, notes, command, bits, runs):
    lines = header_lines(command, bits, "Times") + [""]
    lines.append("Whole commands (positions and triangles as in the sizes table, file reading "
                 "and writing included, default threads), medians of %d interleaved rounds, "
                 "pomar / Draco of the same rounds; peaks are GNU time's maximum resident set "
                 "size, MiB, pomar (Draco)." % runs)
    lines.append("")
    lines.append("| mesh | vertices | encode time / Draco | decode time / Draco | "
                 "encode peak MiB | decode peak MiB |")
    lines.append("|:--|--:|--:|--:|--:|--:|")

    def mb(a, b):
        return "%.1f (%.1f)" % (a, b) if a is not None and b is not None else "n/a"
    for r in rows:
        lines.append("| %s | %s | %.2f | %.2f | %s | %s |" % (
            r["mesh"], format(r["vertices"], ","), r["enc_ratio"], r["dec_ratio"],
            mb(r["enc_mb"], r["denc_mb"]), mb(r["dec_mb"], r["ddec_mb"])))
    lines += [""] + ["- " + n for n in notes] if notes else []
    return lines


def rewrite(readme, name, lines):
    """Replaces the text between README's `name` markers; the markers must exist."""
    begin = "<!-- readme_results:%s begin -->" % name
    end = "<!-- readme_results:%s end -->" % name
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        sys.exit("readme_results: %s has no %s ... %s markers" % (readme, begin, end))
    text = text[:i + len(begin)] + "\n" + "\n".join(lines) + "\n" + text[j:]
    tmp = readme + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, readme)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    which = p.add_mutually_exclusive_group()
    which.add_argument("--sizes-only", action="store_true", help="only the sizes table")
    which.add_argument("--times-only", action="store_true", help="only the times table")
    p.add_argument("--quick", action="store_true", help="samples/bunny.ply only")
    p.add_argument("--readme", default=os.path.join(REPO, "README.md"),
                   help="the file whose marked tables are rewritten (default README.md)")
    p.add_argument("--data", default=os.path.join(REPO, "..", "shared", "data"),
                   help="folder of real meshes (default ../shared/data); rows skipped if absent")
    p.add_argument("--build", default=os.path.join(REPO, "build"), help="CMake build folder")
    p.add_argument("--runs", type=int, default=5, help="interleaved timing rounds (default 5)")
    p.add_argument("--bits", type=int, default=12, help="quantization bits (default 12)")
    args = p.parse_args()
    # The command as written in README.md: --build names where the tools are, not what they
    # measure, so it is left out.
    shown, skip = [], False
    for a in sys.argv[1:]:
        if skip or a.startswith("--build="):
            skip = False
            continue
        if a == "--build":
            skip = True
            continue
        shown.append(a)
    command = " ".join(["python3 bench/readme_results.py"] + shown)

    tools = {}
    for name in ("draco_encoder", "draco_decoder"):
        tools[name] = shutil.which(name)
        if not tools[name]:
            log("%s not on PATH (apt-get install draco): nothing measured" % name)
            sys.exit(SKIP)
    if not os.access(bench.GNU_TIME, os.X_OK) and not args.sizes_only:
        sys.exit("readme_results: %s not found (apt-get install time)" % bench.GNU_TIME)

    with tempfile.TemporaryDirectory(prefix="pomar-readme.") as work:
        for name, rel in (("pomar", "codec/pomar"), ("pomar_gen_mesh", "bench/pomar_gen_mesh")):
            src = os.path.join(args.build, rel)
            if not os.access(src, os.X_OK):
                sys.exit("readme_results: %s not found; build first (cmake -S . -B build -G "
                         "Ninja -DCMAKE_BUILD_TYPE=Release && ninja -C build)" % src)
            tools[name] = os.path.join(work, name)  # a rebuild during the run cannot mix tools
            shutil.copy2(src, tools[name])
        size_rows, time_rows, notes = [], [], []
        for label, name, source in (MESHES[:1] if args.quick else MESHES):
            if source == "samples":
                path = os.path.join(REPO, "samples", name)
            elif source == "data":
                path = os.path.join(os.path.abspath(args.data), name)
                if not os.path.exists(path):
                    notes.append("%s: %s not found (--data DIR)" % (label, path))
                    continue
            else:
                path = name
            path, note = bench.materialize(label, path, source, tools, os.path.join(work, "mesh"))
            if note:
                notes.append(note)
                continue
            log(label + " ...")
            if not args.times_only:
                size_rows.append(sizes_row(label, path, tools, work, args.bits))
            if not args.sizes_only:
                time_rows.append(times_row(label, path, tools, work, args.bits, args.runs))
            shutil.rmtree(os.path.join(work, "mesh"), ignore_errors=True)

    if not args.times_only:
        rewrite(args.readme, "sizes", sizes_block(size_rows, notes, command, args.bits))
    if not args.sizes_only:
        rewrite(args.readme, "times", times_block(time_rows, notes, command, args.bits,
                                                  args.runs))
    log("rewrote %s" % args.readme)
    if not all(r["lossless"] for r in size_rows):
        sys.exit(1)


if __name__ == "__main__":
    main()
