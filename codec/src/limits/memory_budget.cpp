// Memory limits (pomar/limits.h): estimates from measured peaks, the memory available to
// the process, and the check that refuses a mesh before the large allocations.
#include "pomar/limits.h"
#include "pomar/mesh_io.h"

#include "attributes/attribute_quantize.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include <sys/resource.h>

namespace pomar {
namespace {

// ------------------------------------------------------------------ estimates
//
// Linear fits (fixed + per vertex + per face) of the peak resident set size of `pomar
// encode` / `pomar decode` (random access and --progressive files), measured with
// /usr/bin/time on closed meshes (F = 2V) and open strips (F = V, F = 4V/3) of 30k to 2M
// vertices (bench/README.md, "Memory").
//
// Decode (binary PLY output; every output format peaks within 1% of it, the text and STL
// writers writing in 1 MiB chunks; measured at 100k, 300k and 1M vertices, one and two
// threads): least squares 5.0 MiB + 45 B/vertex + 31 B/face (random access), 5.4 MiB + 56
// B/vertex + 29 B/face (progressive), rounded up above every peak of 300k vertices and
// more. The random-access per-vertex term is 56 B so
// that an open strip (F = V, 1M vertices, 24,614 clusters: its second thread takes 24
// B/vertex) stays 0.91 of the estimate on two threads; 1M strips are 0.71-0.73 of it with
// the per-thread part below, the 1M sphere 0.76, spheres and tori with attributes 0.76-0.85.
//
// Encode, per input format (EncodeInput; two encoding threads): peaks of `pomar encode` on
// noisy spheres (F = 2V) of 100k, 300k, 1M and 3M vertices and 2-row strips (F = V) of
// 100k, 300k and 1M, each as binary and ASCII PLY, OBJ, OFF, binary and ASCII STL, and tori
// (F = 2V) with attributes (bench/README.md, "Memory"). Lines through the 300k and 1M
// peaks, raised and rounded so that every peak of 300k vertices and more is 10-25% below
// its estimate.
// The stored errors (section CERR, written by default) add the measure's arrays, 26 B/vertex
// (encode/cluster_error_measure.h), at the peak: binary PLY, two threads, the dragon 89.0 ->
// 100.9 MB and the 1M noisy sphere 195.9 -> 209.5 MB, 0.79 and 0.75 of the row below (within
// the peaks MemoryEstimate.IsAboveTheMeasuredPeaks holds, which were measured higher).
//   - Binary and ASCII PLY, OFF, binary and ASCII STL (read in 4 MiB chunks) and plain OBJ
//     (pomar's own reader: the text and the flat arrays) peak within 3% of each other at
//     300k and 1M (STL 9-11% more at 3M: the weld's table): the encoder's own peak is the
//     maximum. One row, which is also the estimate for a mesh already in memory
//     (EncodeInput::Mesh, the library's check): 12 MiB + 200 B/vertex + 36 B/face (least
//     squares: 6.3 MiB + 170 + 29; the peaks 0.75-0.83 of it). Neither ASCII STL nor plain
//     OBJ holds its whole text beside the arrays, so they need no row of their own.
//   - OBJ through tinyobjloader, positions and faces only (relative or slashed indices,
//     materials, ...): its arrays (an index triple of 12 bytes per corner, ...) and the text
//     peak above the encoder: 16 MiB + 24 B/vertex + 244 B/face (least squares: 16 MiB - 3
//     + 217; the peaks 0.81-0.89 of it).
//   - OBJ through tinyobjloader with normals, texture coordinates or colours: their lines
//     and per-corner indices ("f 1/1/1 ...") held too. Normals and texture coordinates per
//     vertex, tori and strips: least squares about 13 MiB + 23 B/vertex + 285 B/face; 16 MiB
//     + 32 B/vertex + 330 B/face, 0.84-0.88 of it (they peak 1.02-1.18 times the
//     row above). Normals only ("f a//a"), colours only, one normal per face (flat
//     shading: twice as many normals as vertices): 0.67-0.85 of it. Files with still more
//     values (one per corner) hold more than this: encode_input_extra (kObjValueLine).
// STL's size check sees half a vertex per facet (a closed mesh once welded). For an open
// STL mesh (the strips: one vertex per facet) it is too low for the whole encode (binary and
// ASCII STL strips peak at 1.28-1.34 times it) but not for the reading (0.76-0.79); the
// encoder's own check, with the welded counts (EncodeInput::Mesh), comes before its
// allocations and holds them (0.80-0.83).
// OBJ with more normals and texture coordinates than one of each per vertex (one of each
// per corner: 3 'vn' and 3 'vt' lines per face, "f a/ta/na ..."; all of them left out of the
// .pomar, which keeps per-vertex values) holds them beyond the ObjAttributes row: tori of
// 100k, 300k and 1M vertices (F = 2V) peak at 93.5, 281.6 and 893.1 MiB against the row's
// 81.9, 214.2 and 675.9 (1.14-1.32 times); 12-24 bytes per line past 2 per vertex. With 32
// bytes per such line (encode_input_extra) the peaks are 0.83-0.92 of the estimate.
constexpr uint64_t kObjValueLine = 32;

struct Fit {
  uint64_t fixed, per_vertex, per_face;
};
constexpr Fit kLightReaders = {12ull << 20, 200, 36};
constexpr Fit kTinyobjloader = {16ull << 20, 24, 244};
constexpr Fit kTinyobjloaderAttributes = {16ull << 20, 32, 330};

/// The fit of loading `input` and encoding it.
Fit encode_fit(EncodeInput input) {
  switch (input) {
  case EncodeInput::Obj:
    return kTinyobjloader;
  case EncodeInput::ObjAttributes:
    return kTinyobjloaderAttributes;
  default: // the encoder's own peak is the maximum
    return kLightReaders;
  }
}

constexpr uint64_t kDecodeFixed = 8ull << 20;
constexpr uint64_t kClusteredDecodePerVertex = 56;
constexpr uint64_t kClusteredDecodePerFace = 36;
constexpr uint64_t kProgressiveDecodePerVertex = 64;
constexpr uint64_t kProgressiveDecodePerFace = 34;
// Each thread past the first that walks the clustered levels: its claim stamps (4 bytes per
// face), the pipeline's traversed clusters and its allocator arena. Measured with decode
// --threads 1, 2 and 8 (GNU time %M, the larger of 2-3 runs): the average
// of the 7 extra threads of an 8-thread decode is 4.3-5.2 bytes per face (bunny 0.37 MiB,
// noisy spheres 300k 2.76, 1M 8.14, 2M 15.86, dragon 3.98, 1M strips 4.28-5.03 MiB), the
// first extra thread 2-4 MiB more (bunny 0.75, 300k 5.13, 1M 10.95, 2M 18.89, 10M 78.7,
// dragon 7.20, strips 6.66-8.46 MiB; the encoder's at 1M 11.4). 6 MiB + 5 bytes per face:
// the first extra thread 0.71-0.88 of it from 300k faces up. There is no per-vertex term:
// a cluster keeps its marks by rank in the cluster, and the marks by vertex id are the
// global levels', on the calling thread only.
constexpr uint64_t kThreadFixed = 6ull << 20;
constexpr uint64_t kThreadPerFace = 5;

// Per-vertex attributes (bench/README.md, "Memory", attributes): encoding, what tori (F =
// 2V, binary PLY) with colour, normal, quality and UV (8 codes), colour (3) or quality (1)
// peak above the same torus without attributes (the encoder frees its input once
// quantized): 226-243 B/vertex (8 codes), 74-93 (3), 31-41 (1) at 300k and 1M vertices (100k: 262,
// 94, 40). 16 + 34 B per code: each part 0.62-0.85 of its estimate at 300k and 1M, each whole peak
// 0.71-0.80 of the PLY row plus the part. Decoding: 81 B/vertex (8 codes, 27 bytes of values) and
// 12 B/vertex (1 code, 4 bytes): the codes (8 B each) plus the values, plus slack. The lossless
// stage (bench/README.md, "Memory"): noisy spheres of 300k and 1M vertices with 10% of their faces
// duplicated, shuffled, and 5% more vertices no face uses (cut and recorded) peak at 131 and 361
// MiB to encode where the load check's PLY row (input counts) says 94.5 and 287.4, and at 46 and
// 136 MiB to decode where the clustered row says 53.4 and 145.4. The terms: 88 bytes per face on
// top to encode (the encoder's check: the cut mesh's faces), 128 with --keep-order (checked at
// load: the file's faces), two threads' part included, and 32 bytes per vertex and 28 per face to
// undo the record at full resolution. A --keep-order encode of a messy mesh pays the cut's copy and
// the order's work together; of a clean one (no copy of the mesh or the input), 107 and 336 MiB on
// the spheres (decodes 57 and 172), 0.65 of the sums
// (MemoryEstimate.LosslessStageIsAboveTheMeasuredPeaks).
constexpr uint64_t kLosslessEncodePerFace = 88;
constexpr uint64_t kLosslessKeepOrderEncodePerFace = 128;
constexpr uint64_t kLosslessDecodePerVertex = 32;
constexpr uint64_t kLosslessDecodePerFace = 28;

constexpr uint64_t kEncodeAttributeFixed = 16;
constexpr uint64_t kEncodePerAttributeCode = 34;
constexpr uint64_t kDecodePerAttributeCode = 8;
constexpr uint64_t kDecodeAttributeFixed = 16;

/// Integer codes per vertex of one stored attribute (StoredAttribute::codes).
uint32_t code_count(AttributeKind kind, uint32_t components, int bits) {
  StoredAttribute s;
  s.kind = kind;
  s.components = components;
  s.bits = bits;
  return s.codes();
}

/// a + b * c, saturating at UINT64_MAX (counts come from untrusted headers).
uint64_t add_mul(uint64_t a, uint64_t b, uint64_t c) {
  if (c != 0 && b > (UINT64_MAX - a) / c)
    return UINT64_MAX;
  return a + b * c;
}

// ------------------------------------------------------------------ reading /proc and /sys

/// The whole (small) file, or "" if it cannot be read.
std::string slurp(const std::string &path) {
  std::ifstream in(path);
  if (!in)
    return "";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The number after "key" at the start of a line ("MemAvailable:   123 kB"), times
/// `unit`; false if there is no such line.
bool find_field(const std::string &text, const std::string &key, uint64_t unit, uint64_t &out) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) != 0)
      continue;
    const char *p = line.c_str() + key.size();
    while (*p == ' ' || *p == '\t' || *p == ':')
      ++p;
    char *end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(p, &end, 10);
    if (end == p || errno != 0)
      return false;
    out = v > UINT64_MAX / unit ? UINT64_MAX : v * unit;
    return true;
  }
  return false;
}

/// A cgroup limit file: a byte count, or "max" / a huge value for "no limit" (false).
bool read_limit(const std::string &path, uint64_t &out) {
  const std::string text = slurp(path);
  if (text.empty() || text.compare(0, 3, "max") == 0)
    return false;
  char *end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (end == text.c_str() || errno != 0 || v >= (1ull << 60)) // v1 "unlimited" is ~2^63
    return false;
  out = v;
  return true;
}

/// Keeps the smaller bound.
void offer(AvailableMemory &best, uint64_t bytes, const std::string &source) {
  if (!best.known || bytes < best.bytes) {
    best.known = true;
    best.bytes = bytes;
    best.source = source;
  }
}

/// The cgroup paths of this process: "0::/a/b" (v2) and the v1 memory controller's.
void cgroup_paths(const std::string &root, std::string &v2, std::string &v1) {
  std::istringstream in(slurp(root + "/proc/self/cgroup"));
  std::string line;
  while (std::getline(in, line)) {
    const size_t a = line.find(':'), b = a == std::string::npos ? a : line.find(':', a + 1);
    if (b == std::string::npos)
      continue;
    const std::string controllers = "," + line.substr(a + 1, b - a - 1) + ",";
    if (line.compare(0, a, "0") == 0 && b == a + 1)
      v2 = line.substr(b + 1);
    else if (controllers.find(",memory,") != std::string::npos)
      v1 = line.substr(b + 1);
  }
}

/// `dir` and its ancestors up to `top` (both absolute, dir inside top).
std::vector<std::string> up_to(const std::string &top, std::string rel) {
  std::vector<std::string> dirs;
  while (!rel.empty() && rel != "/") {
    dirs.push_back(top + rel);
    rel = rel.substr(0, rel.find_last_of('/'));
  }
  dirs.push_back(top);
  return dirs;
}

/// limit - usage + the page cache the kernel can drop, for every cgroup from this
/// process's up to the root of the hierarchy (a parent's limit binds too).
void offer_cgroups(const std::string &root, AvailableMemory &best) {
  std::string v2, v1;
  cgroup_paths(root, v2, v1);
  struct Kind {
    std::string top, rel, limit, usage, cache, name;
  };
  const Kind kinds[] = {
      {root + "/sys/fs/cgroup", v2, "memory.max", "memory.current", "inactive_file",
       "cgroup memory.max"},
      {root + "/sys/fs/cgroup/memory", v1, "memory.limit_in_bytes", "memory.usage_in_bytes",
       "total_inactive_file", "cgroup memory.limit_in_bytes"},
  };
  for (const Kind &k : kinds)
    for (const std::string &dir : up_to(k.top, k.rel)) {
      uint64_t limit = 0, usage = 0, cache = 0;
      if (!read_limit(dir + "/" + k.limit, limit) || !read_limit(dir + "/" + k.usage, usage))
        continue;
      find_field(slurp(dir + "/memory.stat"), k.cache + " ", 1, cache);
      const uint64_t used = usage - std::min(usage, cache);
      offer(best, limit - std::min(limit, used), k.name);
    }
}

/// RLIMIT_AS against the process's virtual size, RLIMIT_DATA against its data segment.
void offer_rlimits(const std::string &root, AvailableMemory &best) {
  const std::string status = slurp(root + "/proc/self/status");
  const struct {
    int resource;
    const char *field, *name;
  } limits[] = {{RLIMIT_AS, "VmSize", "RLIMIT_AS"}, {RLIMIT_DATA, "VmData", "RLIMIT_DATA"}};
  for (const auto &l : limits) {
    struct rlimit r;
    if (::getrlimit(l.resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY)
      continue;
    uint64_t used = 0;
    find_field(status, l.field, 1024, used);
    const uint64_t cap = static_cast<uint64_t>(r.rlim_cur);
    offer(best, cap - std::min(cap, used), l.name);
  }
}

/// 1,234,567
std::string grouped(uint64_t v) {
  std::string digits = std::to_string(v), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0)
      out += ',';
    out += digits[i];
  }
  return out;
}

std::string lower(std::string s) {
  for (char &c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

} // namespace

EncodeInput encode_input(const LoadReport &report) {
  if (report.format == "ply")
    return report.text ? EncodeInput::PlyAscii : EncodeInput::PlyBinary;
  if (report.format == "stl")
    return report.text ? EncodeInput::StlAscii : EncodeInput::StlBinary;
  if (report.format == "obj")
    return report.plain_obj        ? EncodeInput::ObjPlain
           : report.obj_attributes ? EncodeInput::ObjAttributes
                                   : EncodeInput::Obj;
  if (report.format == "off")
    return EncodeInput::Off;
  return EncodeInput::Mesh;
}

uint64_t encode_input_extra(const LoadReport &report, uint64_t vertices) {
  if (encode_input(report) != EncodeInput::ObjAttributes)
    return 0;
  const uint64_t counted = add_mul(0, vertices, 2); // one normal and one UV per vertex
  return report.obj_value_lines > counted
             ? add_mul(0, report.obj_value_lines - counted, kObjValueLine)
             : 0;
}

uint64_t encode_memory_estimate(uint64_t vertices, uint64_t faces, EncodeInput input) {
  const Fit fit = encode_fit(input);
  return add_mul(add_mul(fit.fixed, vertices, fit.per_vertex), faces, fit.per_face);
}

uint64_t decode_memory_estimate(uint64_t vertices, uint64_t faces, bool clustered) {
  const uint64_t per_vertex = clustered ? kClusteredDecodePerVertex : kProgressiveDecodePerVertex;
  const uint64_t per_face = clustered ? kClusteredDecodePerFace : kProgressiveDecodePerFace;
  return add_mul(add_mul(kDecodeFixed, vertices, per_vertex), faces, per_face);
}

uint64_t lossless_encode_memory(uint64_t faces, bool keep_order) {
  return add_mul(0, faces, keep_order ? kLosslessKeepOrderEncodePerFace : kLosslessEncodePerFace);
}

uint64_t lossless_decode_memory(uint64_t vertices, uint64_t faces) {
  return add_mul(add_mul(0, vertices, kLosslessDecodePerVertex), faces, kLosslessDecodePerFace);
}

uint64_t encode_attribute_bytes_per_vertex(const Mesh &mesh, const AttributeOptions &options) {
  uint64_t codes = 0;
  for (const VertexAttribute &a : mesh.attributes)
    if (options.keep.keeps(a.kind))
      codes += code_count(a.kind, a.components, options.exact ? 0 : 1);
  return codes ? kEncodeAttributeFixed + kEncodePerAttributeCode * codes : 0;
}

uint64_t decode_attribute_bytes_per_vertex(const FileInfo &info, const AttributeMask &keep) {
  uint64_t codes = 0, values = 0;
  for (const AttributeInfo &a : info.attributes) {
    codes += code_count(a.kind, a.components, a.bits);
    if (keep.keeps(a.kind))
      values += a.components * (a.kind == AttributeKind::Colour ? 1 : sizeof(float));
  }
  if (values == 0) // nothing returned: the decoder reads past the codes without storing them
    return 0;
  return kDecodeAttributeFixed + kDecodePerAttributeCode * codes + values;
}

AvailableMemory available_memory(const std::string &root) {
  AvailableMemory best;
  uint64_t bytes = 0;
  if (find_field(slurp(root + "/proc/meminfo"), "MemAvailable", 1024, bytes))
    offer(best, bytes, "MemAvailable");
  offer_cgroups(root, best);
  offer_rlimits(root, best);
  return best;
}

uint64_t parse_memory_size(const std::string &text) {
  const std::string t = lower(text);
  if (t == "none" || t == "unlimited")
    return kNoMemoryLimit;
  if (t == "auto")
    return 0;
  auto bad = [&] {
    return Error(Error::Kind::Usage,
                 "bad memory size '" + text +
                     "': expected bytes or a number with K, M, G or T (e.g. 512M, 1.5GiB), "
                     "'auto' or 'none'");
  };
  size_t digits = 0;
  while (digits < t.size() &&
         (std::isdigit(static_cast<unsigned char>(t[digits])) || t[digits] == '.'))
    ++digits;
  if (digits == 0)
    throw bad();
  const std::string number = t.substr(0, digits), unit = t.substr(digits);
  static const struct {
    const char *name;
    int shift;
  } units[] = {{"", 0},     {"b", 0},   {"k", 10},   {"kb", 10}, {"kib", 10},
               {"m", 20},   {"mb", 20}, {"mib", 20}, {"g", 30},  {"gb", 30},
               {"gib", 30}, {"t", 40},  {"tb", 40},  {"tib", 40}};
  int shift = -1;
  for (const auto &u : units)
    if (unit == u.name)
      shift = u.shift;
  char *end = nullptr;
  const double value = std::strtod(number.c_str(), &end);
  if (shift < 0 || end != number.c_str() + number.size() || !std::isfinite(value))
    throw bad();
  const double bytes = std::ceil(std::ldexp(value, shift));
  if (bytes >= 18446744073709551615.0)
    throw Error(Error::Kind::Usage,
                "memory size '" + text + "' is too large (use 'none' for no limit)");
  return static_cast<uint64_t>(bytes);
}

std::string format_memory_size(uint64_t bytes) {
  if (bytes < 1024)
    return std::to_string(bytes) + " bytes";
  static const char *const units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double v = double(bytes) / 1024;
  int u = 0;
  while (v >= 1024 && u < 5)
    v /= 1024, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  return buf;
}

void check_memory(const char *action, uint64_t vertices, uint64_t faces, uint64_t needed,
                  uint64_t held, uint64_t limit) {
  if (limit == kNoMemoryLimit)
    return;
  std::string have;
  uint64_t need = needed;
  if (limit == 0) { // automatic: the part not yet held against what is available
    const AvailableMemory a = available_memory();
    if (!a.known)
      return;
    need = needed - std::min(needed, held);
    if (need <= a.bytes)
      return;
    have = format_memory_size(a.bytes) + " available (" + a.source + ")";
  } else {
    if (needed <= limit)
      return;
    have = "the limit is " + format_memory_size(limit);
  }
  throw Error(Error::Kind::MemoryLimit,
              std::string("not enough memory to ") + action + " " + grouped(vertices) +
                  " vertices and " + grouped(faces) + " faces: needs about " +
                  format_memory_size(need) + (need != needed ? " more" : "") + ", " + have +
                  "; set the limit with pomar --max-memory or Python's memory_limit=");
}

void check_encode_memory(uint64_t vertices, uint64_t faces, uint64_t limit, uint64_t held,
                         uint64_t attribute_bytes, unsigned threads, EncodeInput input,
                         uint64_t input_extra) {
  uint64_t needed = add_mul(add_mul(encode_memory_estimate(vertices, faces, input), 1, input_extra),
                            vertices, attribute_bytes);
  if (threads > 1)
    needed = add_mul(needed, threads - 1, decode_thread_memory(vertices, faces));
  check_memory("encode", vertices, faces, needed, held, limit);
}

uint64_t decode_thread_memory(uint64_t /*vertices: no per-vertex part*/, uint64_t faces) {
  return add_mul(kThreadFixed, faces, kThreadPerFace);
}

namespace {
/// What decoding a mesh of these counts from the file `info` describes needs: the mesh,
/// its attributes, the threads past the first and, at full resolution (`full`) of a file
/// with a lossless record, undoing the cut.
uint64_t decode_needs(const FileInfo &info, uint64_t v, uint64_t f, bool full,
                      const AttributeMask &keep, unsigned threads) {
  uint64_t needed = add_mul(decode_memory_estimate(v, f, info.clustered()), v,
                            decode_attribute_bytes_per_vertex(info, keep));
  if (info.clustered() && threads > 1)
    needed = add_mul(needed, threads - 1, decode_thread_memory(v, f));
  if (full && info.lossless_bytes > 0)
    needed = add_mul(needed, 1, lossless_decode_memory(info.input_vertices, info.input_faces));
  return needed;
}

/// The whole mesh's vertex and face counts after `level` levels (0: the base mesh; out of
/// range: full resolution).
std::pair<uint64_t, uint64_t> counts_at(const FileInfo &info, int level) {
  if (level == 0)
    return {info.base_vertices, info.base_faces};
  if (level > 0 && static_cast<size_t>(level) <= info.levels.size())
    return {info.levels[size_t(level) - 1].vertices, info.levels[size_t(level) - 1].faces};
  return {info.vertices, info.faces};
}
} // namespace

void check_decode_memory(const FileInfo &info, int level, uint64_t limit, const AttributeMask &keep,
                         unsigned threads) {
  const auto [v, f] = counts_at(info, level);
  const bool full = level < 0 || static_cast<size_t>(level) >= info.levels.size();
  check_memory("decode", v, f, decode_needs(info, v, f, full, keep, threads), 0, limit);
}

namespace {
struct MapNeeds {
  uint64_t vertices = 0, faces = 0, bytes = 0;
};
MapNeeds level_map_needs(const FileInfo &info, const std::vector<int> &levels, int base_level,
                         const AttributeMask &keep, unsigned threads) {
  MapNeeds out;
  if (levels.empty())
    return out;
  const auto [lo, hi] = std::minmax_element(levels.begin(), levels.end());
  auto [v, f] = counts_at(info, *hi); // a whole-mesh level: exact
  if (*lo != *hi) {
    const auto [base_v, base_f] = counts_at(info, base_level);
    double grow_v = 0, grow_f = 0; // (sums of 32-bit counts over the clusters: doubles)
    for (int t : levels) {
      const auto [tv, tf] = counts_at(info, t);
      grow_v += double(tv) - double(base_v);
      grow_f += double(tf) - double(base_f);
    }
    const double n = double(levels.size());
    v = std::min(v, base_v + uint64_t(std::ceil(1.3 * grow_v / n)));
    f = std::min(f, base_f + uint64_t(std::ceil(1.3 * grow_f / n)));
  }
  const bool full = static_cast<size_t>(*lo) >= info.levels.size();
  out.vertices = v;
  out.faces = f;
  out.bytes = decode_needs(info, v, f, full, keep, threads);
  return out;
}
} // namespace

uint64_t level_map_memory_estimate(const FileInfo &info, const std::vector<int> &levels,
                                   int base_level, const AttributeMask &keep, unsigned threads,
                                   uint64_t *vertices, uint64_t *faces) {
  const MapNeeds n = level_map_needs(info, levels, base_level, keep, threads);
  if (vertices)
    *vertices = n.vertices;
  if (faces)
    *faces = n.faces;
  return n.bytes;
}

void check_level_map_memory(const FileInfo &info, const std::vector<int> &levels, int base_level,
                            uint64_t held, uint64_t limit, const AttributeMask &keep,
                            unsigned threads) {
  if (levels.empty())
    return;
  const MapNeeds n = level_map_needs(info, levels, base_level, keep, threads);
  check_memory("refine the clusters asked for to about", n.vertices, n.faces, n.bytes, held, limit);
}

} // namespace pomar
