"""Edits of .pomar files for the exit-status tests: XXH32 (the format's checksum), the
section table (docs/format.md "Version 4: sections") and rewriting a section body or the
header with every checksum made right again.

  python3 pomar_file.py info.json IN OUT EDIT [ARG]
EDIT: version N (the header's format version), section-byte TAG OFFSET VALUE (a body byte,
checksums fixed), section-cut TAG BYTES (the body cut to BYTES, checksums fixed),
section-tag TAG NEW (the tag renamed, header checksum fixed), flip-section TAG (a body byte
flipped, checksum left stale)."""
import json
import struct
import sys

M = 0xFFFFFFFF
P1, P2, P3, P4, P5 = 2654435761, 2246822519, 3266489917, 668265263, 374761393


def rotl(x, r):
    return ((x << r) | (x >> (32 - r))) & M


def xxh32(data, seed=0):
    n, i = len(data), 0
    if n >= 16:
        v = [(seed + P1 + P2) & M, (seed + P2) & M, seed, (seed - P1) & M]
        while i + 16 <= n:
            for k in range(4):
                lane = struct.unpack_from("<I", data, i + 4 * k)[0]
                v[k] = (rotl((v[k] + lane * P2) & M, 13) * P1) & M
            i += 16
        h = (rotl(v[0], 1) + rotl(v[1], 7) + rotl(v[2], 12) + rotl(v[3], 18)) & M
    else:
        h = (seed + P5) & M
    h = (h + n) & M
    while i + 4 <= n:
        h = (rotl((h + struct.unpack_from("<I", data, i)[0] * P3) & M, 17) * P4) & M
        i += 4
    while i < n:
        h = (rotl((h + data[i] * P5) & M, 11) * P1) & M
        i += 1
    h ^= h >> 15
    h = (h * P2) & M
    h ^= h >> 13
    h = (h * P3) & M
    return h ^ (h >> 16)


def main():
    info, src, dst, edit, *args = sys.argv[1:]
    i = json.load(open(info))
    data = bytearray(open(src, "rb").read())
    header = i["header_bytes"]
    assert xxh32(data[: header - 4]) == struct.unpack_from("<I", data, header - 4)[0]
    sections = i["sections"]
    table = header - 4 - 20 * len(sections)  # entries: tag, flags, u64 bytes, XXH32
    body, entry = header + i["base_bytes"], {}
    for k, s in enumerate(sections):
        entry[s["name"]] = (table + 20 * k, body, s["bytes"])
        body += s["bytes"]
    if edit == "version":
        struct.pack_into("<H", data, 8, int(args[0]))
    elif edit == "flip-section":
        _, at, size = entry[args[0]]
        data[at + size // 2] ^= 0x10
    else:
        e, at, size = entry[args[0]]
        if edit == "section-tag":
            data[e : e + 4] = args[1].encode()
        elif edit == "section-byte":
            data[at + int(args[1])] = int(args[2])
        elif edit == "section-cut":
            cut = int(args[1])
            del data[at + cut : at + size]
            size = cut
            struct.pack_into("<Q", data, e + 8, size)
        struct.pack_into("<I", data, e + 16, xxh32(data[at : at + size]))
        struct.pack_into("<I", data, header - 4, xxh32(data[: header - 4]))
    open(dst, "wb").write(data)


main()
