// pomar: progressive, randomly accessible compression of manifold triangle meshes.
//
// This is the core API on flat arrays (positions + 32-bit triangle indices). It has no
// dependency on vcglib; `pomar/vcg_adapter.h` converts from/to vcglib meshes and
// `pomar/mesh_io.h` reads and writes PLY/OBJ/OFF/STL files.
//
// Installed as a CMake package (`find_package(pomar CONFIG)`: pomar::core for this header,
// random_access.h, repair.h and limits.h; pomar::io adds mesh_io.h) and for pkg-config
// (`pomar`). vcg_adapter.h is header-only and uses the program's own vcglib.
//
// Threads: the library has no global mutable state. Every free function (encode, decode,
// inspect, check_blocks, make_manifold, load_mesh, save_mesh, ...) may be called from
// several threads at once, on different or on the same (unmodified) inputs. An object
// (SelectiveDecoder, FileSource, MemorySource) is used by one thread at a time; distinct
// objects are independent. Callbacks (Progress, SizeCheck) run on the calling thread,
// before the function returns. encode (decimation) and decode (the clusters of a random-
// access file) also work on threads of their own (EncodeOptions::threads,
// DecodeOptions::threads, SelectiveOptions::threads; 0 = the cores available), all joined
// before they return (a SelectiveDecoder keeps its idle threads until it is destroyed);
// results do not depend on the thread count.
//
// Ownership: functions take inputs by const reference or as (pointer, size) and do not
// keep them after returning (exception: MemorySource, see random_access.h); results are
// returned by value and belong to the caller.
#pragma once

#include "pomar/version.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pomar/attributes.h"

namespace pomar {

/// The version of the library the program runs with, "MAJOR.MINOR.PATCH" (compare with
/// the POMAR_VERSION_* macros of pomar/version.h, the headers it was compiled with).
const char *version();

/// Every failure of the library is reported as a pomar::Error whose what() is one line
/// naming the problem (and, for invalid meshes, where: counts and one example). kind()
/// says what sort of failure it is, for callers that react differently (the tool's exit
/// status, a plugin's message) without reading the text.
class Error : public std::runtime_error {
public:
  enum class Kind {
    Other,         ///< none of the below (errors thrown by callers with a message only)
    InvalidMesh,   ///< an input mesh or mesh file that cannot be used: not manifold, NaN,
                   ///< no triangles, indices out of range, a malformed PLY/OBJ/OFF/STL file
    DamagedFile,   ///< a .pomar file that fails its checks or is not one at all
    TruncatedFile, ///< a .pomar file that ends before the data asked for
    Unsupported,   ///< a .pomar version (or feature) this library cannot read
    Io,            ///< a file that cannot be opened, read, written or renamed
    MemoryLimit,   ///< the work would need more memory than allowed (see pomar/limits.h)
    Usage,         ///< a bad argument: a level or cluster that does not exist, a bad option
    Internal,      ///< a broken invariant of the codec itself (a bug: please report it)
  };
  /// No location: block() is kNoBlock.
  static constexpr int kNoBlock = -1;

  explicit Error(const std::string &what) : std::runtime_error(what) {}
  Error(Kind kind, const std::string &what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const noexcept { return kind_; }

  /// The file the message names, if any (mesh files; .pomar files read by path).
  const std::string &path() const noexcept { return path_; }
  Error &with_path(const std::string &path) {
    path_ = path;
    return *this;
  }
  /// DamagedFile / TruncatedFile: the level or cluster block the damage is in, which a
  /// decode with skip_damaged can decode around (kNoBlock: elsewhere, or not known).
  int level() const noexcept { return level_; }
  int64_t cluster() const noexcept { return cluster_; }
  Error &in_block(int level, int64_t cluster = kNoBlock) {
    level_ = level;
    cluster_ = cluster;
    return *this;
  }
  bool in_block() const noexcept { return level_ != kNoBlock || cluster_ != kNoBlock; }

private:
  Kind kind_ = Kind::Other;
  std::string path_;
  int level_ = kNoBlock;
  int64_t cluster_ = kNoBlock;
};

/// A material of a textured mesh: an OBJ `newmtl` block, a PLY/MeshLab texture.
struct Material {
  std::string name;       ///< OBJ: the `newmtl` name; PLY/MeshLab: "texture_<i>"
  int32_t texture = -1;   ///< index into Mesh::texture_files (its map_Kd), or -1: none
  std::string properties; ///< the block's other lines (Kd, Ks, Ns, illum, ...), as read
};

/// A triangle mesh as flat arrays: x,y,z per vertex and three vertex indices per
/// triangle, counter-clockwise seen from outside; optionally per-vertex attributes
/// (pomar/attributes.h), per-corner texture coordinates with a material per face, and the
/// texture files the texture coordinates refer to.
struct Mesh {
  std::vector<float> positions;    // 3 * vertex_count()
  std::vector<uint32_t> triangles; // 3 * triangle_count()
  std::vector<VertexAttribute> attributes;
  std::vector<std::string> texture_files; ///< metadata, kept as given
  /// Embedded texture images: texture_images[i] holds the bytes of texture_files[i] (empty:
  /// not embedded), or the vector is empty. encode() stores them in the file (one .pomar is
  /// then a self-contained asset); decode() gives them back bit for bit.
  std::vector<std::vector<uint8_t>> texture_images;
  /// Per-corner texture coordinates (MeshLab's wedge texcoords, OBJ `f v/vt`, PLY face
  /// `texcoord`): u, v of corner k of triangle f at [6 f + 2 k], or empty. A vertex whose
  /// corners differ is on a seam; the codec keeps every corner's value (on a grid over
  /// their range, or bit for bit) and never opens a seam at a coarser level.
  std::vector<float> corner_texcoords;
  /// Per-triangle material: an index into `materials`, or empty (no materials).
  std::vector<uint32_t> face_materials;
  std::vector<Material> materials;
  /// Set on decoded per-corner texture coordinates: 0 = exact, else the quantization bits;
  /// `corner_texcoord_bound` the largest error of a component against the input.
  int corner_texcoord_bits = 0;
  double corner_texcoord_bound = 0;
  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return triangles.size() / 3; }
  /// The first attribute of this kind (and this name, if given), or nullptr.
  const VertexAttribute *find(AttributeKind kind, const std::string &name = {}) const;
  VertexAttribute *find(AttributeKind kind, const std::string &name = {});
};

/// Throw pomar::Error naming the attribute (and vertex) if an attribute does not fit the
/// mesh: wrong component count, value count not matching the vertex count, empty or
/// repeated name; with `quantized`, also NaN/infinite values (zero-length normals are fine).
/// Attributes whose kind `mask` drops are not checked.
void validate_attributes(const Mesh &mesh, bool quantized, const AttributeMask &mask = {});

/// Progress callback: fraction in [0,1] and a short stage name ("decimate", "encode", ...).
using Progress = std::function<void(double fraction, const char *stage)>;

struct EncodeOptions {
  int bits = 12; ///< quantization bits per coordinate, 4..24
  /// Random access: the number of clusters is about `clusters` if non-zero, else
  /// `cluster_ratio` x vertices (default 1%, the low end of the paper's advised 1-5%:
  /// fewer clusters mean a smaller global part and less to read for one region).
  uint32_t clusters = 0;
  double cluster_ratio = 0.01;
  bool progressive = false; ///< pure progressive mode: global levels only, no clusters
  /// Threads for the encoder's parallel steps (decimation's candidate evaluation, the
  /// clustered levels); 0 = the cores this process may run on. The file does not depend on
  /// it.
  unsigned threads = 0;
  /// With threads > 1, a clustered level started on a mesh of fewer vertices than this is
  /// recorded and coded on the calling thread: on small levels the parallel phases cost
  /// more than they save. 0: every level on the threads. The file does not depend on it.
  uint32_t min_parallel_vertices = 4096;
  Progress progress; ///< optional
  /// Peak memory allowed, in bytes: encode() throws pomar::Error before its large
  /// allocations if it would need more (pomar/limits.h). 0 = automatic (the memory
  /// available to the process), UINT64_MAX (kNoMemoryLimit) = do not check.
  uint64_t memory_limit = 0;
  /// Which attributes are stored and how precisely (default: all, normals within 0.33°,
  /// scalars on 16 bits, texture coordinates on 12 bits over their ranges).
  AttributeOptions attributes;
  /// Refuse meshes the codec must cut to code (non-manifold, inconsistently oriented,
  /// duplicate or degenerate faces) and drop unreferenced vertices: the file then has no
  /// lossless record. Off: such meshes are cut and the cut is stored (LosslessReport).
  bool strict = false;
  /// Store the input vertex numbering too (messy and clean meshes alike: the file then
  /// carries a lossless record): a full decode gives the vertices back in the input order.
  bool keep_order = false;
  /// The format to write: 5 (each split's patch coded as a placement rank, about 1 bit per
  /// vertex smaller), or 4: the layout of versions 1, 3 and 4 (readers that predate
  /// version 5 read it).
  int format_version = 5;
  /// Random-access files of version 5: store the cluster blocks in the Morton order of the
  /// clusters' roots (section BLKO, required), so that the blocks of one region lie
  /// together in the file. Off: the blocks in cluster id order. On by default.
  bool spatial_layout = true;
  /// Random-access files of version 5: store a geometric error per cluster and level
  /// (section CERR, optional; about 1% of the file: each bound a whole power of two, at most
  /// twice the error), bounded while the clustered levels are
  /// coded, for view-dependent decoding (SelectiveDecoder::want_view). On by default.
  bool cluster_errors = true;
  /// Random-access files of version 5: store 8 more bits of every cluster block's checksum
  /// (section BCHK, optional; 1 byte per cluster: 16-bit checks), so that a damaged block is found
  /// by a region decode or `--skip-damaged` however its data decodes. On by default.
  bool block_checks = true;
  /// Measurement of a layout of tiers (bench/README.md, "Tiers of clustered levels: measured
  /// cost"; pomar_ra_bench tiers, not a tool option): decimate the rounds down to the
  /// clusters' count in tiers of `tier_rounds` rounds, each on a grid of cells holding about
  /// `tier_cell_vertices` vertices at the tier's start, collapsing only inside a cell, the
  /// cells' border vertices locked. The file is an ordinary file (the levels are just
  /// collapses). 0 = off (the default).
  uint32_t tier_rounds = 0;
  uint32_t tier_cell_vertices = 1024;
};

/// What the codec stored to give a mesh back exactly although it had to cut it (the
/// lossless record, format version 4). All zero for a clean mesh.
struct LosslessReport {
  bool stored = false;              ///< the file carries a lossless record
  size_t vertex_copies = 0;         ///< decoded vertices that are one input vertex (cuts)
  size_t vertices_split = 0;        ///< input vertices cut into several
  size_t edges_cut = 0;             ///< non-manifold or non-orientable edges cut
  size_t faces_flipped = 0;         ///< faces reversed to orient the coded mesh
  size_t duplicate_faces = 0;       ///< exact duplicates kept in the record
  size_t degenerate_faces = 0;      ///< faces repeating a vertex kept in the record
  size_t unreferenced_vertices = 0; ///< vertices no coded face uses, kept in the record
  bool keep_order = false;          ///< the input vertex numbering is stored
  size_t seam_edges = 0;            ///< texture seam edges (per-corner values differ across)
  size_t wedge_copies = 0;          ///< of vertex_copies, those made at texture seams
  uint64_t bytes = 0;               ///< size of the record (the LSLS section body)
  /// "non-manifold: 421 vertices and 12 edges stored as cuts; 3 duplicate faces kept; ...",
  /// "" if nothing was stored.
  std::string summary() const;
};

/// One refinement level of a file: the mesh it produces and what it costs.
struct LevelInfo {
  uint32_t vertices = 0; ///< vertex count after decoding this level
  uint32_t faces = 0;    ///< face count after decoding this level
  uint64_t connectivity_bytes = 0;
  uint64_t geometry_bytes = 0;
};

/// Quantization grid shared by encoder and decoder: a cube of side `extent` from `origin`,
/// 2^bits - 1 steps. Dequantization is defined here so everybody gets the same floats.
struct Quantizer {
  float origin[3] = {0, 0, 0};
  float extent = 0;
  int bits = 12;
  double step() const;
  float dequantize(int axis, uint32_t q) const;
  uint32_t quantize(int axis, float x) const; ///< nearest grid index, clamped to the grid
};

/// An attribute stored in a file (its ATTR section).
struct AttributeInfo {
  AttributeKind kind = AttributeKind::Scalar;
  std::string name;
  uint32_t components = 0;
  int bits = 0;       ///< 0 = exact
  double bound = 0;   ///< as VertexAttribute::bound
  uint64_t bytes = 0; ///< its coded residuals
};

/// What a .pomar file holds (read from its header and level table only).
struct FileInfo {
  uint32_t version = 0;
  int bits = 0;
  Quantizer grid;                ///< the exact grid of the file
  float bbox_min[3] = {0, 0, 0}; ///< grid origin
  float bbox_max[3] = {0, 0, 0}; ///< grid origin + extent (the grid is a cube)
  uint32_t vertices = 0;         ///< at full resolution
  uint32_t faces = 0;
  uint32_t base_vertices = 0;
  uint32_t base_faces = 0;
  std::vector<LevelInfo> levels; ///< levels[i] = refinement level i+1
  uint64_t total_bytes = 0;
  uint64_t header_bytes = 0;       ///< header + level table
  uint64_t base_bytes = 0;         ///< the stored base mesh
  uint64_t connectivity_bytes = 0; ///< sum over levels (clustered part: encoder's estimate)
  uint64_t geometry_bytes = 0;     ///< sum over levels (clustered part: encoder's estimate)
  // Random access (clustered files; zero/absent in pure progressive files).
  /// levels decoded for the whole mesh (= levels.size() if progressive)
  uint32_t global_levels = 0;
  uint32_t clusters = 0;     ///< vertices of the base clustered mesh = clusters
  uint64_t global_bytes = 0; ///< header, base mesh, global levels, tables, index
  uint64_t tables_bytes = 0, index_bytes = 0, cluster_bytes = 0;
  std::vector<uint32_t> cluster_block_bytes; ///< filled by inspect()
  /// Per-vertex attributes (filled by inspect(); empty if the file has none).
  std::vector<AttributeInfo> attributes;
  std::vector<std::string> texture_files;
  /// Per texture file: the bytes of its embedded image (0: not embedded; filled by inspect()).
  std::vector<uint64_t> embedded_texture_bytes;
  uint64_t attribute_bytes = 0; ///< the whole ATTR section
  /// Version 4: bytes of the lossless record (0 = none): undone by a full decode.
  uint64_t lossless_bytes = 0;
  /// What a full decode gives (the input's counts): vertices/faces above are those of the
  /// coded mesh, which differ when the file carries a lossless record (filled by inspect()).
  uint64_t input_vertices = 0, input_faces = 0;
  /// Version 4: what the file carries in sections of its global part, with their sizes.
  struct Section {
    std::string name;      ///< four ASCII characters, e.g. "LSLS"
    uint64_t bytes = 0;    ///< size of the section's body
    bool required = false; ///< a reader that does not know it must refuse the file
  };
  std::vector<Section> sections;
  bool clustered() const { return clusters != 0; }
};

/// Ideal code lengths per symbol kind, in bits.
struct SymbolBits {
  double s_v = 0;        ///< split flags
  double s_e = 0;        ///< which ring edge is v_to-v_ref
  double faces = 0;      ///< patch size s_l + s_r
  double s_l = 0;        ///< where the patch starts
  double rank = 0;       ///< version 5: the patch's placement (in place of s_e and s_l)
  double tangential = 0; ///< geometry residuals in the tangent plane (two per split)
  double normal = 0;     ///< geometry residual along the normal
};

/// Facts about one encode, beyond what the file itself says.
struct EncodeReport {
  FileInfo info;
  size_t input_vertices = 0;
  /// No triangle uses them: dropped with `strict`, else kept in the lossless record.
  size_t unreferenced_vertices = 0;
  double quantize_seconds = 0, decimate_seconds = 0, encode_seconds = 0;
  /// Ideal code length per symbol kind of the global levels (adaptive models).
  SymbolBits symbol_bits;
  /// decoded vertex i (in a full decode) is input vertex decoded_to_input[i].
  std::vector<uint32_t> decoded_to_input;
  LosslessReport lossless; ///< what was stored to undo the cut
  /// Clustered files: for cluster c (block c) and clustered level j (level
  /// global_levels + 1 + j), cluster_level_ends[c * clustered levels + j] is the size its
  /// block had once the range coder had coded that level (the prefix holding levels
  /// 0..j, up to the coder's few pending bytes).
  std::vector<uint32_t> cluster_level_ends;
  /// With EncodeOptions::tier_rounds: the tiers, finest first. Levels are refinement
  /// levels (the tier refines levels first_level .. first_level + levels - 1); cells are
  /// cubes of side 2^cell_bits grid units, shifted by half a side when `shifted`;
  /// longest_edge (grid units) is the mesh's longest edge after the tier's levels.
  struct Tier {
    int first_level = 0, levels = 0, cell_bits = 0;
    bool shifted = false;
    uint32_t vertices = 0, cells = 0, border = 0; ///< after the tier's levels
    double longest_edge = 0;
  };
  std::vector<Tier> tiers;
};

/// Encode a triangle mesh. The codec codes manifold, consistently oriented meshes: any other
/// mesh is first cut into one (make_manifold, pomar/repair.h) and what the cut changed is
/// stored (format version 4), so that a full decode gives back exactly the input: its
/// vertex count, its oriented faces as a multiset (duplicates and faces repeating a vertex
/// included), every vertex on its grid position (vertex order too with keep_order).
/// Throws pomar::Error on a NaN or an index out of range, a mesh with no valid triangle,
/// and, with `strict`, on any mesh that needs cutting.
std::vector<uint8_t> encode(const Mesh &mesh, const EncodeOptions &options = {},
                            EncodeReport *report = nullptr);
/// The same (the same file), taking the mesh: a mesh coded as it is (manifold, oriented,
/// every vertex used, or `strict`) is freed as soon as it is quantized and its attributes
/// coded, so that the encoder's peak memory does not hold it as well. `mesh` is left empty,
/// whether encode returns or throws.
std::vector<uint8_t> encode(Mesh &&mesh, const EncodeOptions &options = {},
                            EncodeReport *report = nullptr);

/// Drops the vertices no triangle uses (the others keep their order, triangles are
/// renumbered; indices out of range are left as they are); returns how many were dropped.
size_t drop_unreferenced_vertices(Mesh &mesh);

/// Read the header, base mesh and level table of a .pomar image (checks their checksums).
FileInfo inspect(const uint8_t *data, size_t size);

/// Decode the mesh after `level` refinement levels (0 = base mesh, -1 = full resolution).
/// Throws pomar::Error if the image is damaged or truncated (checked per block), or, right
/// after reading the header, if the mesh would need more memory than `memory_limit` (bytes;
/// 0 = automatic, UINT64_MAX = do not check; see pomar/limits.h).
Mesh decode(const uint8_t *data, size_t size, int level = -1, const Progress &progress = {},
            uint64_t memory_limit = 0);

/// Throws pomar::Error (Kind::Usage) "level L does not exist: the file has levels 0..F"
/// unless 0 <= level <= finest.
void check_level_exists(int level, int finest);

/// A block of a .pomar file that failed its checks (checksum, structure, or missing from a
/// truncated file) and was skipped by a decode with `skip_damaged`.
struct DamagedBlock {
  std::string block;   ///< "cluster 17", "level 9", or "cluster data" (see below)
  std::string problem; ///< what is wrong with it (the error the strict decoder reports)
  /// The region it codes stays at this level. -1 for "cluster data": all blocks together
  /// fail their checksum (format version 3) though each passes its own 8-bit check, so the
  /// damaged one cannot be located and skipped; the mesh may be wrong in places.
  int level_kept = 0;
  int level = -1;       ///< the global level it holds (1-based), -1 for a cluster block
  int64_t cluster = -1; ///< the cluster whose block it is, -1 for a global level
};

struct DecodeOptions {
  int level = -1; ///< 0 = base mesh, -1 = full resolution
  /// Decode around damage instead of failing: a damaged global level stops the decoding
  /// at the level before it; a damaged cluster block leaves that cluster at the base
  /// clustered level and its neighbours at most one level finer per step of distance
  /// (the level map rule), everything else is decoded as asked. Every skipped block is
  /// listed in DecodeReport::damaged. Damage in the header, base mesh, model tables or
  /// cluster index still fails: nothing can be decoded without them.
  bool skip_damaged = false;
  Progress progress; ///< optional
  /// Peak memory allowed, in bytes, checked right after the header (0 = automatic,
  /// UINT64_MAX = do not check; see pomar/limits.h).
  uint64_t memory_limit = 0;
  /// Which stored attributes the returned mesh carries (AttributeMask::none(): positions
  /// and triangles only; the codes, interleaved with the positions, are then read past
  /// without being stored or predicted: less memory and time).
  AttributeMask attributes;
  /// Threads for the clustered levels of a random-access file (their clusters are decoded
  /// in parallel); 0 = the cores this process may run on; at most 8 (each further one holds
  /// about 5 bytes per face: pomar/limits.h decode_thread_memory). The mesh does not
  /// depend on it.
  /// Global levels, and so pure progressive files, are decoded on one thread.
  unsigned threads = 0;
  /// With threads > 1, a clustered level with less work than this (its vertices per
  /// cluster times the clusters to refine, from the level table) is decoded on the calling
  /// thread: on small levels the parallel phases cost more than they save. 0: every level
  /// on the threads. The mesh does not depend on it.
  uint32_t min_parallel_vertices = 4096;
};

struct DecodeReport {
  std::vector<DamagedBlock> damaged; ///< empty when the file is intact
  int level = 0;                     ///< the finest level decoded anywhere
  /// Clustered files with damage: clusters decoded below the requested level.
  uint32_t clusters_below_request = 0;
  /// Clustered files: the level map's decode rounds (SelectiveDecoder::decode_rounds): 1,
  /// plus one per decode again from the base clustered mesh after blocks that passed their
  /// checks failed while they were decoded.
  uint32_t decode_rounds = 0;
};

/// One line per block of blocks[first..], "  cluster 17 (kept at level 16): problem" (no
/// level for damage that could not be located), at most `max_lines` of them, then
/// "  ... and N more"; lines joined by '\n', no trailing newline. For warnings.
/// `text` safe to print on a terminal or in a dialog: control characters, DEL and bytes
/// that are not valid UTF-8 become "\xNN" (valid UTF-8 stays as it is). Every message and
/// listing of the tool, the plugins and the Python module passes text that comes from a file
/// (names, texture file names, materials) through it.
std::string printable(const std::string &text);

std::string describe_damage(const std::vector<DamagedBlock> &blocks, size_t first = 0,
                            size_t max_lines = 10);

/// decode() with options; `*report` (optional) says what was skipped.
Mesh decode(const uint8_t *data, size_t size, const DecodeOptions &options,
            DecodeReport *report = nullptr);

/// Check every block's checksum without decoding (the header, base mesh, model tables and
/// cluster index must be intact: that throws). Returns the damaged or missing blocks,
/// empty for an intact file. Cluster blocks carry an 8-bit check in the index, 16 or 32 bits
/// with a BCHK section: a damaged block passes it with probability 1/256 (2^-16, 2^-32),
/// which a decode (with its structural checks) may still catch.
/// Textured files need their base mesh decoded: `memory_limit` bounds that decode as
/// DecodeOptions::memory_limit does (0 = the memory available).
std::vector<DamagedBlock> check_blocks(const uint8_t *data, size_t size, uint64_t memory_limit = 0);

} // namespace pomar
