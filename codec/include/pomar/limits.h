// Memory limits: refuse a mesh that will not fit in memory before allocating for it, with
// a clear pomar::Error, rather than let the machine swap or the kernel kill the process.
//
//   estimate     what encoding (loading included) or decoding (writing included) a mesh of
//                V vertices and F faces needs at its peak, from measured peaks
//                (bench/README.md, "Memory"), rounded up;
//   available    what the process may still use: the smallest of MemAvailable, the
//                cgroup's limit minus its usage and RLIMIT_AS/RLIMIT_DATA minus the
//                process's use, "unknown" when none can be read;
//   check        throws when the estimate is above the limit: an explicit byte count, or
//                0 = automatic (available memory; no check when it is unknown), or
//                kNoMemoryLimit = no check.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

struct LoadReport; // pomar/mesh_io.h

/// The memory limit meaning "do not check".
constexpr uint64_t kNoMemoryLimit = UINT64_MAX;

/// Where an encode's mesh comes from: the mesh readers hold different amounts on the way
/// (tinyobjloader's arrays and the whole OBJ text), so the peak of loading and encoding
/// depends on the input format and, for OBJ, on the reader that takes the file
/// (bench/README.md, "Memory", per input format).
enum class EncodeInput {
  Mesh,          ///< a pomar::Mesh in memory, or a reader that holds little more (the default)
  PlyBinary,     ///< binary PLY
  PlyAscii,      ///< ASCII PLY
  ObjPlain,      ///< OBJ of plain "v" and "f" lines only, through pomar's own reader
  Obj,           ///< OBJ through tinyobjloader, without per-vertex attributes
  ObjAttributes, ///< OBJ through tinyobjloader, with normals, texture coordinates or colours
  Off,           ///< OFF
  StlBinary,     ///< binary STL
  StlAscii,      ///< ASCII STL (read in chunks)
};

/// The EncodeInput of a mesh file from what load_mesh has set in its LoadReport when it
/// calls its size check: `format` ("ply", "obj", "off", "stl"), `text`, `plain_obj` and
/// `obj_attributes`; EncodeInput::Mesh for any other format name.
EncodeInput encode_input(const LoadReport &report);

/// What reading the file of `report` (with `vertices` vertices) holds beyond its
/// EncodeInput's estimate: for an OBJ read by tinyobjloader, 32 bytes per normal or texture
/// coordinate line past one of each per vertex (the values and their text: a file with one
/// of each per corner, 3 of each per face, peaks 1.3 times the row without this). 0 for the
/// other readers.
uint64_t encode_input_extra(const LoadReport &report, uint64_t vertices);

/// Peak resident memory of loading a mesh file and encoding it (`pomar encode`), for a mesh
/// of this many vertices and faces read from `input`. Conservative: 10-25% above the
/// measured peaks.
uint64_t encode_memory_estimate(uint64_t vertices, uint64_t faces,
                                EncodeInput input = EncodeInput::Mesh);

/// Peak resident memory of decoding a mesh of this size and writing it out (`pomar
/// decode`); `clustered` files (random access) need a little more than progressive ones.
uint64_t decode_memory_estimate(uint64_t vertices, uint64_t faces, bool clustered);

/// What the lossless stage adds to the encode peak (a mesh cut, or given with keep_order:
/// the input and the cut mesh held together, the record's maps and the canonical face
/// order): 88 bytes per face, 128 with keep_order (`faces`: the input's).
uint64_t lossless_encode_memory(uint64_t faces, bool keep_order);

/// What undoing the cut adds to a full-resolution decode of a file with a lossless record
/// (the decoded and the output mesh held together, the canonical face order): 32 bytes
/// per vertex and 28 per face.
uint64_t lossless_decode_memory(uint64_t vertices, uint64_t faces);

/// What per-vertex attributes add to the encode peak, per vertex, for the attributes
/// `options` keeps of `mesh` (0 without): their integer codes (docs/format.md: colour 3-4,
/// quantized normal 2, exact normal 3, scalar 1, texcoord 2) in the encoder's copies, and
/// the reader's path for files with attributes. Measured, rounded up (bench/README.md,
/// "Memory").
uint64_t encode_attribute_bytes_per_vertex(const Mesh &mesh, const AttributeOptions &options);

/// What per-vertex attributes add to the decode peak, per vertex, for the file's attributes
/// (`info.attributes`, filled by inspect() or from the ATTR section) of which the decoder
/// returns those `keep` keeps: their codes (not stored at all when `keep` keeps none of
/// them) and the returned values.
uint64_t decode_attribute_bytes_per_vertex(const FileInfo &info, const AttributeMask &keep);

/// Memory this process may still use, and which bound gave it.
struct AvailableMemory {
  bool known = false; ///< false: nothing could be read (then nothing is refused)
  uint64_t bytes = 0; ///< the smallest bound
  std::string source; ///< "MemAvailable", "cgroup memory.max", "RLIMIT_AS", ...
};

/// Reads /proc/meminfo, the process's cgroup (v2 memory.max/memory.current or v1
/// memory.limit_in_bytes/memory.usage_in_bytes, each ancestor too, page cache that can be
/// dropped counted as free) and RLIMIT_AS/RLIMIT_DATA against /proc/self/status. `root`
/// is prepended to the /proc and /sys paths (for tests; the rlimits are the process's own).
AvailableMemory available_memory(const std::string &root = "");

/// Parses a memory size: a plain byte count ("1048576"), or a number (decimals allowed)
/// with a unit K, M, G or T, optionally followed by "B" or "iB", any case ("512M", "2G",
/// "1.5GiB", "64kb"); units are powers of 1024. "none" (or "unlimited") gives
/// kNoMemoryLimit and "auto" gives 0. Throws pomar::Error naming the text otherwise.
uint64_t parse_memory_size(const std::string &text);

/// "18.2 GiB", "512.0 MiB", "900 bytes".
std::string format_memory_size(uint64_t bytes);

/// Throws pomar::Error if `needed` bytes do not fit in `limit` (0 = automatic, see above):
/// "not enough memory to <action> <V> vertices and <F> faces: needs about 18.2 GiB, 7.1 GiB
/// available (MemAvailable); set the limit with pomar --max-memory or Python's
/// memory_limit=". `held` is what the
/// caller already holds of `needed` (the input mesh): an automatic check compares the rest
/// with what is available; an explicit limit bounds the whole peak.
void check_memory(const char *action, uint64_t vertices, uint64_t faces, uint64_t needed,
                  uint64_t held, uint64_t limit);

/// check_memory with encode_memory_estimate for `input` plus `input_extra` bytes
/// (encode_input_extra), plus `attribute_bytes` per vertex
/// (encode_attribute_bytes_per_vertex), plus decode_thread_memory per thread past the first
/// recording the clustered levels (`threads`: EncodeOptions::threads resolved and capped
/// like the decoder's, decode_threads) (action "encode").
void check_encode_memory(uint64_t vertices, uint64_t faces, uint64_t limit, uint64_t held = 0,
                         uint64_t attribute_bytes = 0, unsigned threads = 1,
                         EncodeInput input = EncodeInput::Mesh, uint64_t input_extra = 0);

/// What each decoding thread past the first adds to decode_memory_estimate for a clustered
/// file (and each encoding thread to encode_memory_estimate): its claim stamps, the
/// traversed clusters waiting to be applied and its allocator arena, 6 MiB + 5 bytes per
/// face (`vertices` is not used any more).
uint64_t decode_thread_memory(uint64_t vertices, uint64_t faces);

/// check_memory with decode_memory_estimate for the mesh of `level` (-1 = full resolution)
/// of the file `info` describes, plus decode_attribute_bytes_per_vertex(info, keep) per
/// vertex, plus decode_thread_memory per thread past the first of a clustered file's decode
/// on `threads` threads (DecodeOptions::threads resolved), plus lossless_decode_memory for
/// the full resolution of a file with a lossless record (action "decode").
void check_decode_memory(const FileInfo &info, int level, uint64_t limit,
                         const AttributeMask &keep = AttributeMask(), unsigned threads = 1);

/// check_decode_memory for a selective decode's level map (SelectiveDecoder::update):
/// `levels` holds each cluster's level, `base_level` is the base clustered mesh's, `held`
/// bytes are held already (the mesh decoded so far: what an automatic limit does not count
/// again). The map's counts are estimated from the level table: a whole-mesh level's, exact;
/// otherwise the base clustered mesh (one vertex per cluster) plus 1.3 times the average
/// growth of a cluster from base_level to each cluster's level (the clusters of a scan
/// differ: on the dragon, regions of 1,600-2,500 clusters grew 1.13-1.37 times the average,
/// one of almost every cluster 0.89 times), at most the whole mesh at the map's finest
/// level. Plus lossless_decode_memory when the map is the full resolution of a file with a
/// lossless record (SelectiveDecoder::exact_mesh undoes the cut). Action "refine the
/// clusters asked for to about".
void check_level_map_memory(const FileInfo &info, const std::vector<int> &levels, int base_level,
                            uint64_t held, uint64_t limit,
                            const AttributeMask &keep = AttributeMask(), unsigned threads = 1);

/// The bytes check_level_map_memory compares with the limit (and, if asked, the map's
/// estimated vertex and face counts).
uint64_t level_map_memory_estimate(const FileInfo &info, const std::vector<int> &levels,
                                   int base_level, const AttributeMask &keep = AttributeMask(),
                                   unsigned threads = 1, uint64_t *vertices = nullptr,
                                   uint64_t *faces = nullptr);

} // namespace pomar
