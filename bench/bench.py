#!/usr/bin/env python3
"""pomar vs Draco benchmark: compression (bits per vertex), speed, peak memory, losslessness.

    python3 bench/bench.py [--quick] [--csv out.csv] [--data DIR] [--no-generated] [--bits N]

Prints one markdown report on stdout (machine, main table, scaling table, random-access
tables from pomar_ra_bench unless --quick); progress goes to stderr. Python 3 standard library
only. Needs a built tree (pomar, pomar_gen_mesh, pomar_ra_bench), the Debian `draco` package
(draco_encoder/draco_decoder) and GNU time (/usr/bin/time).
See bench/README.md for what every column means.
"""

import argparse
import csv
import datetime
import json
import os
import shutil
import statistics
import struct
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESH_EXTS = (".ply", ".obj", ".off", ".stl")
CLEAN_DATA = ["bunny.ply", "horse.ply", "armadillo_50k.obj", "fertility_23k.off",
              "rocker_arm.off", "bimba_9k.off", "dragon.ply.xz"]
GENERATED = [100_000, 300_000, 1_000_000]  # noisy_sphere target vertex counts
SINGLE_RUN_VERTICES = 400_000  # meshes at least this large are timed once (dragon, 1M sphere)
# Random-access section (pomar_ra_bench; skipped with --quick): (label, file, source) where
# source is "samples", "data" (relative to --data) or "generated" (target vertex count).
RA_CURVE = [("samples/bunny.ply", "bunny.ply", "samples"), ("data/horse.ply", "horse.ply", "data")]
RA_ONE = [("data/dragon.ply", "dragon.ply.xz", "data"),
          ("gen/noisy_sphere_100k", 100_000, "generated")]
GNU_TIME = "/usr/bin/time"


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------------------------
# Running and measuring
# --------------------------------------------------------------------------------------------

class Run:
    def __init__(self, rc, seconds, peak_mb, stderr):
        self.rc, self.seconds, self.peak_mb, self.stderr = rc, seconds, peak_mb, stderr


def measure(cmd, workdir):
    """Runs cmd under GNU time. Wall seconds: perf_counter around the process (GNU time's %e
    has only 10 ms resolution; %e is the fallback). Peak memory: %M (max RSS, KiB) -> MiB."""
    tfile = os.path.join(workdir, "time.txt")
    if os.path.exists(tfile):
        os.remove(tfile)
    start = time.perf_counter()
    proc = subprocess.run([GNU_TIME, "-f", "%e %M", "-o", tfile] + cmd,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seconds = time.perf_counter() - start
    peak_mb = None
    try:
        with open(tfile) as f:
            last = [line for line in f.read().splitlines() if line.strip()][-1].split()
        if seconds <= 0:
            seconds = float(last[0])
        peak_mb = int(last[1]) / 1024.0
    except (OSError, IndexError, ValueError):
        pass
    return Run(proc.returncode, seconds, peak_mb, proc.stderr.decode(errors="replace"))


def first_error_line(text):
    """The codec's error message (skips any stray diagnostic lines)."""
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    for line in lines:
        if "error" in line.lower() or "fail" in line.lower():
            return line
    return lines[-1] if lines else "(no message)"


def timed_runs(cmd, runs, workdir, output=None):
    """Runs cmd `runs` times; returns (median seconds, max peak MiB, last Run) or the failing Run."""
    results = []
    for _ in range(runs):
        if output and os.path.exists(output):
            os.remove(output)
        r = measure(cmd, workdir)
        if r.rc != 0 or (output and not (os.path.exists(output) and os.path.getsize(output) > 0)):
            if r.rc == 0:
                r.rc = -1
                r.stderr += "\nno output file written"
            return None, None, r
        results.append(r)
    peaks = [r.peak_mb for r in results if r.peak_mb is not None]
    return (statistics.median(r.seconds for r in results),
            max(peaks) if peaks else None, results[-1])


# --------------------------------------------------------------------------------------------
# Inputs Draco cannot read (OFF, ASCII STL) -> position-only binary PLY
# --------------------------------------------------------------------------------------------

def write_ply(path, positions, faces):
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\nelement face %d\n"
                 "property list uchar uint vertex_indices\nend_header\n"
                 % (len(positions), len(faces))).encode())
        f.write(b"".join(struct.pack("<3f", *p) for p in positions))
        f.write(b"".join(struct.pack("<B3I", 3, *t) for t in faces))


def off_to_ply(src, dst):
    tokens = []
    with open(src) as f:
        for line in f:
            tokens.extend(line.split("#", 1)[0].split())
    if tokens[0] != "OFF":  # COFF/NOFF/... carry extra per-vertex values: not needed here
        raise ValueError("unsupported OFF variant " + tokens[0])
    nv, nf = int(tokens[1]), int(tokens[2])
    pos = 4
    positions = []
    for _ in range(nv):
        positions.append(tuple(float(t) for t in tokens[pos:pos + 3]))
        pos += 3
    faces = []
    for _ in range(nf):
        n = int(tokens[pos])
        idx = [int(t) for t in tokens[pos + 1:pos + 1 + n]]
        pos += 1 + n  # (per-face colors are not supported; clean meshes have none)
        for k in range(1, n - 1):  # fan triangulation
            faces.append((idx[0], idx[k], idx[k + 1]))
    write_ply(dst, positions, faces)


def is_binary_stl(path):
    size = os.path.getsize(path)
    if size < 84:
        return False
    with open(path, "rb") as f:
        f.seek(80)
        (n,) = struct.unpack("<I", f.read(4))
    return size == 84 + 50 * n


def ascii_stl_to_ply(src, dst):
    index, positions, faces, corners = {}, [], [], []
    with open(src, errors="replace") as f:
        for line in f:
            t = line.split()
            if len(t) == 4 and t[0] == "vertex":
                p = (float(t[1]), float(t[2]), float(t[3]))
                if p not in index:  # weld exact duplicates, as STL readers do
                    index[p] = len(positions)
                    positions.append(p)
                corners.append(index[p])
            elif t and t[0] == "endfacet":
                if len(corners) == 3:
                    faces.append(tuple(corners))
                corners = []
    write_ply(dst, positions, faces)


def draco_input(path, workdir):
    """A file draco_encoder can read with the same geometry as `path`."""
    ext = os.path.splitext(path)[1].lower()
    if ext in (".ply", ".obj") or (ext == ".stl" and is_binary_stl(path)):
        return path
    dst = os.path.join(workdir, "draco_input.ply")
    if ext == ".off":
        off_to_ply(path, dst)
    else:
        ascii_stl_to_ply(path, dst)
    return dst


# --------------------------------------------------------------------------------------------
# One mesh
# --------------------------------------------------------------------------------------------

def bench_mesh(label, path, args, tools, workdir, source):
    row = {"mesh": label, "source": source, "file": path}
    pomar_file = os.path.join(workdir, "out.pomar")
    decoded = os.path.join(workdir, "decoded.ply")
    for f in (pomar_file, decoded):
        if os.path.exists(f):
            os.remove(f)

    # First encode: validity check (invalid meshes are skipped), then info.
    enc_cmd = [tools["pomar"], "encode", path, pomar_file, "--bits", str(args.bits), "-q"]
    r = measure(enc_cmd, workdir)
    if r.rc != 0 or not os.path.exists(pomar_file):
        row["skip"] = "pomar encode failed (exit %d): %s" % (r.rc, first_error_line(r.stderr))
        return row
    info = subprocess.run([tools["pomar"], "info", pomar_file, "--json"],
                          capture_output=True, text=True)
    if info.returncode != 0:
        row["skip"] = "pomar info failed: " + first_error_line(info.stderr)
        return row
    meta = json.loads(info.stdout)
    nv = int(meta["vertices"])
    row.update(vertices=nv, faces=int(meta["faces"]), levels=int(meta["level_count"]),
               conn_bpv=float(meta["connectivity_bpv"]), geom_bpv=float(meta["geometry_bpv"]),
               bpv=float(meta["bpv"]), pomar_bytes=int(meta["total_bytes"]))
    runs = 1 if nv >= SINGLE_RUN_VERTICES else args.runs
    row["runs"] = runs

    # Timings (the validity run above is a warm-up and is not counted).
    enc_s, enc_mb, r = timed_runs(enc_cmd, runs, workdir, pomar_file)
    if enc_s is None:
        row["skip"] = "pomar encode failed on a timed run: " + first_error_line(r.stderr)
        return row
    # Decode on every core (the default) and on one: the clusters of a random-access file
    # decode in parallel, progressive files on one thread anyway.
    dec1_s, _, _ = timed_runs([tools["pomar"], "decode", pomar_file, decoded, "-q",
                               "--threads", "1"], runs, workdir, decoded)
    dec_s, dec_mb, r = timed_runs([tools["pomar"], "decode", pomar_file, decoded, "-q"],
                                  runs, workdir, decoded)
    row.update(enc_s=enc_s, enc_mb=enc_mb, dec_s=dec_s, dec1_s=dec1_s, dec_mb=dec_mb)
    if dec_s is None:
        row["note"] = "pomar decode failed: " + first_error_line(r.stderr)
        row["lossless"] = "no"
    else:
        # Lossless: the decoded file (decoder + writer) against the original mesh.
        v = subprocess.run([tools["pomar"], "verify", path, pomar_file, decoded],
                           capture_output=True, text=True)
        row["lossless"] = "yes" if v.returncode == 0 else "no"
        if v.returncode != 0:
            row["note"] = "verify exit %d: %s" % (v.returncode, first_error_line(v.stderr + v.stdout))

    # Draco, same quantization, compression level 7, positions only.
    if not args.no_draco:
        try:
            dsrc = draco_input(path, workdir)
        except (OSError, ValueError) as e:
            row["draco_note"] = "draco input conversion failed: %s" % e
            return row
        drc = os.path.join(workdir, "out.drc")
        ddec = os.path.join(workdir, "draco_decoded.ply")
        denc_cmd = [tools["draco_encoder"], "-i", dsrc, "-o", drc, "-qp", str(args.bits),
                    "-cl", "7", "--skip", "NORMAL", "--skip", "TEX_COORD", "--skip", "GENERIC"]
        d_enc_s, d_enc_mb, r = timed_runs(denc_cmd, runs, workdir, drc)
        if d_enc_s is None:
            row["draco_note"] = "draco_encoder failed: " + first_error_line(r.stderr)
            return row
        d_dec_s, d_dec_mb, r = timed_runs([tools["draco_decoder"], "-i", drc, "-o", ddec],
                                          runs, workdir, ddec)
        row.update(draco_bytes=os.path.getsize(drc), draco_bpv=8.0 * os.path.getsize(drc) / nv,
                   draco_enc_s=d_enc_s, draco_dec_s=d_dec_s, draco_enc_mb=d_enc_mb,
                   draco_dec_mb=d_dec_mb)
        row["size_ratio"] = row["pomar_bytes"] / row["draco_bytes"]
        row["enc_ratio"] = enc_s / d_enc_s if d_enc_s else None
        if d_dec_s is not None and dec_s is not None and d_dec_s > 0:
            row["dec_ratio"] = dec_s / d_dec_s
            row["dec1_ratio"] = ratio(dec1_s, d_dec_s)
        row["enc_mb_ratio"] = ratio(enc_mb, d_enc_mb)
        row["dec_mb_ratio"] = ratio(dec_mb, d_dec_mb)
        if d_dec_s is None:
            row["draco_note"] = "draco_decoder failed: " + first_error_line(r.stderr)
        else:
            dv = ply_vertex_count(ddec)
            if dv is not None and dv != nv:
                row["draco_note"] = ("Draco's decoded mesh has %s vertices (pomar: %s)"
                                     % (format(dv, ","), format(nv, ",")))
    return row


def ratio(a, b):
    """a / b, or None when either is unknown (a failed run, no GNU time figure) or b is 0."""
    return a / b if a is not None and b else None


def ply_vertex_count(path):
    try:
        with open(path, "rb") as f:
            for _ in range(64):
                line = f.readline().decode(errors="replace").split()
                if line[:2] == ["element", "vertex"]:
                    return int(line[2])
                if line[:1] == ["end_header"]:
                    break
    except (OSError, ValueError, IndexError):
        pass
    return None


def materialize(label, path, source, tools, mesh_dir):
    """The mesh file to encode: generated meshes are written by pomar_gen_mesh, .xz files are
    decompressed, into mesh_dir. Returns (path, None) or (None, note)."""
    os.makedirs(mesh_dir, exist_ok=True)
    if source == "generated":
        out = os.path.join(mesh_dir, "sphere.ply")
        g = subprocess.run([tools["pomar_gen_mesh"], "noisy_sphere", str(path), out],
                           capture_output=True, text=True)
        if g.returncode != 0:
            return None, "%s: pomar_gen_mesh failed: %s" % (label, first_error_line(g.stderr))
        return out, None
    if path.endswith(".xz"):
        out = os.path.join(mesh_dir, os.path.basename(path)[:-3])
        with open(out, "wb") as f:
            if subprocess.run(["xz", "-dc", path], stdout=f).returncode != 0:
                return None, "%s: xz -d failed" % label
        return out, None
    return path, None


def random_access(args, tools, workdir, data):
    """Runs pomar_ra_bench curve / one on the RA_CURVE / RA_ONE meshes. Returns (list of
    markdown blocks, list of notes)."""
    blocks, notes = [], []
    if "pomar_ra_bench" not in tools:
        return blocks, ["pomar_ra_bench not found in the build folder: rebuild to get this section"]
    jobs = [("curve", m) for m in RA_CURVE] + [("one", m) for m in RA_ONE]
    for mode, (label, name, source) in jobs:
        if source == "generated" and args.no_generated:
            continue
        if source == "samples":
            path = os.path.join(REPO, "samples", name)
        elif source == "data":
            path = os.path.join(data, name)
        else:
            path = name
        if source != "generated" and not os.path.exists(path):
            notes.append("%s %s: %s not found" % (mode, label, path))
            continue
        mesh_dir = os.path.join(workdir, "ra_mesh")
        path, note = materialize(label, path, source, tools, mesh_dir)
        if note:
            notes.append(note)
            continue
        log("bench: pomar_ra_bench %s %s ..." % (mode, label))
        t0 = time.perf_counter()
        r = subprocess.run([tools["pomar_ra_bench"], mode, path, "--bits", str(args.bits)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        log("bench: pomar_ra_bench %s %s done in %.1f s" % (mode, label, time.perf_counter() - t0))
        shutil.rmtree(mesh_dir, ignore_errors=True)
        if r.returncode != 0:
            notes.append("pomar_ra_bench %s %s failed (exit %d): %s"
                         % (mode, label, r.returncode, first_error_line(r.stderr)))
            continue
        blocks.append(r.stdout.strip().replace(os.path.basename(path), label, 1))
    return blocks, notes


# --------------------------------------------------------------------------------------------
# Report
# --------------------------------------------------------------------------------------------

COLUMNS = [  # (header, key, format)
    ("mesh", "mesh", "s"), ("vertices", "vertices", "int"), ("levels", "levels", "d"),
    ("pomar conn bpv", "conn_bpv", ".2f"), ("pomar geom bpv", "geom_bpv", ".2f"),
    ("pomar bpv", "bpv", ".2f"), ("pomar enc s", "enc_s", ".3f"), ("pomar dec s", "dec_s", ".3f"),
    ("pomar dec s 1 thread", "dec1_s", ".3f"),
    ("enc peak MB", "enc_mb", ".1f"), ("dec peak MB", "dec_mb", ".1f"),
    ("lossless", "lossless", "s"), ("draco bpv", "draco_bpv", ".2f"),
    ("draco enc s", "draco_enc_s", ".3f"), ("draco dec s", "draco_dec_s", ".3f"),
    ("draco enc MB", "draco_enc_mb", ".1f"), ("draco dec MB", "draco_dec_mb", ".1f"),
    ("size pomar/draco", "size_ratio", ".2f"), ("enc pomar/draco", "enc_ratio", ".2f"),
    ("dec pomar/draco", "dec_ratio", ".2f"), ("dec 1 thread pomar/draco", "dec1_ratio", ".2f"),
    ("enc MB pomar/draco", "enc_mb_ratio", ".2f"),
    ("dec MB pomar/draco", "dec_mb_ratio", ".2f"),
]
CSV_KEYS = ["mesh", "source", "vertices", "faces", "levels", "runs", "conn_bpv", "geom_bpv", "bpv",
            "pomar_bytes", "enc_s", "dec_s", "dec1_s", "enc_mb", "dec_mb", "lossless", "draco_bytes",
            "draco_bpv", "draco_enc_s", "draco_dec_s", "draco_enc_mb", "draco_dec_mb",
            "size_ratio", "enc_ratio", "dec_ratio", "dec1_ratio", "enc_mb_ratio", "dec_mb_ratio", "note",
            "draco_note"]


def fmt(value, spec):
    if value is None:
        return "n/a"
    if spec == "s":
        return str(value)
    if spec == "int":
        return "{:,}".format(value)
    return format(value, spec)


def markdown_table(headers, rows, right_from=1):
    out = ["| " + " | ".join(headers) + " |",
           "|" + "|".join(":--" if i < right_from else "--:" for i in range(len(headers))) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def machine_lines(load_at_start):
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.lower().startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    nproc = subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip() or str(os.cpu_count())
    mem = ""
    try:
        with open("/proc/meminfo") as f:
            kb = int(f.readline().split()[1])
        mem = ", %.1f GiB RAM" % (kb / 1024 / 1024)
    except (OSError, ValueError, IndexError):
        pass
    now = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    commit = subprocess.run(["git", "-C", REPO, "describe", "--always", "--dirty"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    draco = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "draco"],
                           capture_output=True, text=True).stdout.strip() or "unknown version"
    load = ""
    if load_at_start is not None:
        load = ", 1-min load average %.2f at start, %.2f at end" % (load_at_start, os.getloadavg()[0])
    return ["- Machine: %s, nproc %s%s%s" % (cpu, nproc, mem, load),
            "- Date: %s; pomar at git %s; Draco %s (Debian)" % (now, commit, draco)]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true",
                   help="only samples/ and the ~100k-vertex generated sphere")
    p.add_argument("--csv", metavar="FILE", help="also write the main table as CSV")
    p.add_argument("--data", metavar="DIR", default=os.path.join(REPO, "..", "shared", "data"),
                   help="folder of real meshes (default: ../shared/data relative to the repo)")
    p.add_argument("--no-generated", action="store_true", help="skip the generated spheres")
    p.add_argument("--bits", type=int, default=12,
                   help="quantization bits: pomar --bits and draco -qp (default 12)")
    p.add_argument("--runs", type=int, default=3,
                   help="timed runs per measurement, median reported (default 3; meshes of "
                        ">= %d vertices always 1)" % SINGLE_RUN_VERTICES)
    p.add_argument("--build", default=os.path.join(REPO, "build"), help="CMake build folder")
    p.add_argument("--no-draco", action="store_true", help="skip the Draco columns")
    p.add_argument("--generated", metavar="N,N,...",
                   help="vertex counts of the generated spheres (default %s)"
                        % ",".join(str(n) for n in GENERATED))
    p.add_argument("--no-random-access", action="store_true",
                   help="skip the random-access section")
    args = p.parse_args()
    t_start = time.perf_counter()
    load_at_start = os.getloadavg()[0] if hasattr(os, "getloadavg") else None

    with tempfile.TemporaryDirectory(prefix="pomar-bench.") as workdir:
        # Snapshot the executables so a rebuild during the run cannot mix two versions.
        tools = {}
        for name, rel in (("pomar", "codec/pomar"), ("pomar_gen_mesh", "bench/pomar_gen_mesh"),
                          ("pomar_ra_bench", "bench/pomar_ra_bench")):
            src = os.path.join(args.build, rel)
            if not os.access(src, os.X_OK):
                if name == "pomar_ra_bench":
                    continue  # only the random-access section is skipped (with a note)
                sys.exit("bench.py: %s not found; build first: cmake -S . -B build -G Ninja "
                         "-DCMAKE_BUILD_TYPE=Release && ninja -C build" % src)
            tools[name] = os.path.join(workdir, name)
            shutil.copy2(src, tools[name])
        for name in ("draco_encoder", "draco_decoder"):
            tools[name] = shutil.which(name)
            if not tools[name] and not args.no_draco:
                sys.exit("bench.py: %s not found (apt-get install draco) or use --no-draco" % name)
        if not os.access(GNU_TIME, os.X_OK):
            sys.exit("bench.py: %s not found (apt-get install time)" % GNU_TIME)

        # Inputs: (label, path, source)
        inputs = []
        samples = os.path.join(REPO, "samples")
        if os.path.isdir(samples):
            for name in sorted(os.listdir(samples)):
                if name.lower().endswith(MESH_EXTS):
                    inputs.append(("samples/" + name, os.path.join(samples, name), "samples"))
        data = os.path.abspath(args.data)
        notes = []
        if not args.quick:
            if os.path.isdir(data):
                for name in CLEAN_DATA:
                    path = os.path.join(data, name)
                    if os.path.exists(path):
                        inputs.append(("data/" + name.replace(".xz", ""), path, "data"))
                    else:
                        notes.append("data/%s: not found in %s" % (name, data))
            else:
                notes.append("real meshes: %s not found (use --data DIR)" % data)
        sizes = [int(n) for n in args.generated.split(",")] if args.generated else GENERATED
        generated = [] if args.no_generated else (sizes[:1] if args.quick else sizes)
        for n in generated:
            inputs.append(("gen/noisy_sphere_%dk" % (n // 1000), n, "generated"))

        rows = []
        for label, path, source in inputs:
            mesh_dir = os.path.join(workdir, "mesh")
            path, note = materialize(label, path, source, tools, mesh_dir)
            if note:
                notes.append(note)
                continue
            log("bench: %s ..." % label)
            t0 = time.perf_counter()
            row = bench_mesh(label, path, args, tools, workdir, source)
            log("bench: %s done in %.1f s%s" % (label, time.perf_counter() - t0,
                                                  " (skipped)" if "skip" in row else ""))
            if "skip" in row:
                notes.append("%s: skipped, %s" % (label, row["skip"]))
            else:
                for key in ("note", "draco_note"):
                    if row.get(key):
                        notes.append("%s: %s" % (label, row[key]))
                rows.append(row)
            shutil.rmtree(mesh_dir, ignore_errors=True)

        ra_blocks, ra_notes = [], []
        if not args.quick and not args.no_random_access:
            ra_blocks, ra_notes = random_access(args, tools, workdir, data)

        elapsed = time.perf_counter() - t_start
        single = [r["mesh"] for r in rows if r.get("runs") == 1 and args.runs != 1]

        # ---- report ----
        print("## pomar benchmark (%d-bit quantization)\n" % args.bits)
        print("\n".join(machine_lines(load_at_start)))
        print("- Timings: wall-clock median of %d runs%s; peak MB = max resident set size "
              "(GNU time %%M, MiB); bpv = bits per referenced vertex.\n"
              % (args.runs, " (1 run for %s)" % ", ".join(single) if single else ""))
        columns = [c for c in COLUMNS if not (args.no_draco and "draco" in c[0])]
        print(markdown_table([c[0] for c in columns],
                             [[fmt(r.get(k), f) for _, k, f in columns] for r in rows]))
        if notes:
            print("\nNotes:")
            for n in notes:
                print("- " + n)

        gen_rows = [r for r in rows if r["source"] == "generated"]
        if gen_rows:
            print("\n### scaling (generated noisy spheres)\n")
            print(markdown_table(
                ["mesh", "vertices", "encode s", "decode s", "encode µs/vertex",
                 "decode µs/vertex", "enc peak MB", "dec peak MB"],
                [[r["mesh"], fmt(r["vertices"], "int"), fmt(r["enc_s"], ".3f"),
                  fmt(r.get("dec_s"), ".3f"), fmt(1e6 * r["enc_s"] / r["vertices"], ".2f"),
                  fmt(1e6 * r["dec_s"] / r["vertices"] if r.get("dec_s") else None, ".2f"),
                  fmt(r["enc_mb"], ".1f"), fmt(r.get("dec_mb"), ".1f")] for r in gen_rows]))
        if ra_blocks or ra_notes:
            print("\n### random access (pomar_ra_bench)\n")
            print("\n\n".join(ra_blocks))
            if ra_notes:
                print("\nNotes:")
                for n in ra_notes:
                    print("- " + n)
        print("\nTotal benchmark run time: %.0f s" % elapsed)

        if args.csv:
            with open(args.csv, "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=CSV_KEYS, extrasaction="ignore")
                w.writeheader()
                for r in rows:
                    w.writerow({k: ("%.6g" % r[k]) if isinstance(r.get(k), float) else r.get(k, "")
                                for k in CSV_KEYS})
            log("bench: wrote %s" % args.csv)


if __name__ == "__main__":
    main()
