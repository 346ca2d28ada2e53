// STL: binary/ASCII detection, binary read here (see read_binary_stl for why), ASCII
// through vcglib; identical corners welded. Writing ASCII formatted here, binary through
// vcglib's exporter.
#include "io/io_common.h"

#include <pomar/vcg_adapter.h>

#include <wrap/io_trimesh/export_stl.h>
#include <wrap/io_trimesh/import_stl.h>
#include <wrap/io_trimesh/io_mask.h> // export_stl.h uses it without including it

#include <charconv>
#include <climits>
#include <cmath>
#include <string_view>

namespace pomar::io {
namespace {

using StlImporter = vcg::tri::io::ImporterSTL<IoMesh>;

/// Binary or ASCII, and the facet count of a binary file.
struct StlKind {
  bool binary = false;
  uint64_t facets = 0; // binary only
};

/// Tells binary from ASCII STL: binary if the size is exactly what the facet count in the
/// header says (binary headers may start with "solid" too), else ASCII if it starts with
/// "solid", else binary if a byte > 127 follows the header (vcglib's rule, which without
/// the "solid" test takes an ASCII file with a non-ASCII name for binary). Refuses a
/// truncated binary file and an ASCII one vcglib would hang on.
StlKind classify_stl(const std::string &path) {
  FileReader in(path);
  const uint64_t size = in.remaining();
  unsigned char head[84 + 1000];
  const size_t probe = static_cast<size_t>(std::min<uint64_t>(size, sizeof head));
  if (size < 84 || !in.read(head, probe))
    fail(path, "too short to be an STL file (" + num(size) + " bytes)");
  StlKind kind;
  kind.facets = uint64_t(head[80]) | uint64_t(head[81]) << 8 | uint64_t(head[82]) << 16 |
                uint64_t(head[83]) << 24;
  const uint64_t expected = 84 + 50 * kind.facets;
  const unsigned char *text =
      std::find_if(head, head + probe, [](unsigned char c) { return !std::isspace(c); });
  const bool solid = head + probe - text >= 5 && std::memcmp(text, "solid", 5) == 0;
  kind.binary =
      size == expected ||
      (!solid && std::any_of(head + 84, head + probe, [](unsigned char b) { return b > 127; }));
  if (kind.binary) {
    if (size < expected)
      fail(path, "truncated binary STL (header says " + num(kind.facets) +
                     " facets, file has room for " + num((size - 84) / 50) + ")");
    if (3 * kind.facets > UINT32_MAX)
      fail(path, "binary STL with " + num(kind.facets) + " facets exceeds 32-bit indices");
    return kind;
  }
  // vcglib skips the first line with a getc() loop that never ends without a '\n'.
  bool newline = std::find(head, head + probe, '\n') != head + probe;
  for (int c = 0; !newline && (c = in.get()) >= 0;)
    newline = c == '\n';
  if (!newline)
    fail(path, "not an STL file (ASCII STL without line breaks)");
  return kind;
}

/// Merges vertices with exactly equal coordinates (compared as floats, so -0 equals +0;
/// the positions are finite), keeping the first occurrence's position and the order of
/// first occurrences. Returns the number of vertices merged away. An open-addressing table
/// of kept vertex ids over the coordinates' bits (-0 made +0): a binary STL of 2M facets has
/// 6M corners to look up.
size_t weld_identical(Mesh &mesh) {
  const size_t n = mesh.vertex_count();
  const float *p = mesh.positions.data();
  const auto bits = [p](size_t v, uint32_t b[3]) {
    const float c[3] = {p[3 * v] + 0.0f, p[3 * v + 1] + 0.0f, p[3 * v + 2] + 0.0f}; // -0 -> +0
    std::memcpy(b, c, sizeof c);
  };
  size_t slots = 16;
  while (slots < 2 * n)
    slots *= 2;
  std::vector<uint32_t> table(slots, UINT32_MAX); // kept vertex id, UINT32_MAX = empty
  std::vector<uint32_t> kept_from;                // kept vertex -> its first corner
  kept_from.reserve(n / 2 + 1);
  std::vector<uint32_t> remap(n);
  for (size_t i = 0; i < n; ++i) {
    uint32_t b[3];
    bits(i, b);
    uint64_t h = (uint64_t(b[0]) * 0x9E3779B97F4A7C15ull) ^
                 (uint64_t(b[1]) * 0xC2B2AE3D27D4EB4Full) ^
                 (uint64_t(b[2]) * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    for (size_t at = size_t(h) & (slots - 1);; at = (at + 1) & (slots - 1)) {
      const uint32_t k = table[at];
      if (k == UINT32_MAX) { // first occurrence
        table[at] = remap[i] = static_cast<uint32_t>(kept_from.size());
        kept_from.push_back(static_cast<uint32_t>(i));
        break;
      }
      uint32_t o[3];
      bits(kept_from[k], o);
      if (o[0] == b[0] && o[1] == b[1] && o[2] == b[2]) {
        remap[i] = k;
        break;
      }
    }
  }
  std::vector<float> kept(3 * kept_from.size());
  for (size_t k = 0; k < kept_from.size(); ++k)
    std::copy(p + 3 * size_t(kept_from[k]), p + 3 * size_t(kept_from[k]) + 3, &kept[3 * k]);
  for (auto &t : mesh.triangles)
    t = remap[t];
  mesh.positions.swap(kept);
  return n - mesh.vertex_count();
}

/// Binary STL: 80-byte header, uint32 facet count, then per facet a normal, three corners
/// (little-endian floats) and a 16-bit attribute (a color in some dialects). Read here
/// rather than with vcglib's OpenBinary, which strlen()s the unterminated 80-byte header
/// (a stack over-read) and leaks two FILE handles per call. Same result: 3 new vertices
/// per facet, in file order.
Mesh read_binary_stl(const std::string &path, uint64_t facets, bool &colored) {
  FileReader in(path);
  in.skip(84);
  Mesh mesh;
  mesh.positions.resize(static_cast<size_t>(9 * facets));
  mesh.triangles.resize(static_cast<size_t>(3 * facets));
  colored = false;
  unsigned char rec[50];
  for (size_t f = 0; f < facets; ++f) {
    if (!in.read(rec, sizeof rec)) // classify_stl checked the size already
      fail(path, "truncated binary STL (facet " + num(f) + ")");
    for (size_t c = 0; c < 9; ++c) {
      const unsigned char *b = rec + 12 + 4 * c;
      const uint32_t bits =
          b[0] | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
      std::memcpy(&mesh.positions[9 * f + c], &bits, 4);
    }
    for (uint32_t k = 0; k < 3; ++k)
      mesh.triangles[3 * f + k] = static_cast<uint32_t>(3 * f + k);
    colored |= rec[48] != 0 || rec[49] != 0;
  }
  return mesh;
}

/// What ASCII STL is read in (StlTokens, count_occurrences).
constexpr size_t kStlChunk = size_t(4) << 20;

/// The tokens of a file separated by spaces, tabs, CR and LF (as split_ws), one at a time,
/// read in chunks of 4 MiB: an ASCII STL of millions of facets is never whole in memory.
/// A token returned stays valid until the next call.
class StlTokens {
public:
  explicit StlTokens(const std::string &path) : in_(path), path_(path) {}
  /// The next token; false at the end of the file.
  bool next(std::string_view &out) {
    // (A loop per character: find_first_of with a set calls memchr for each one.)
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
    for (;;) {
      while (pos_ < buf_.size() && blank(buf_[pos_]))
        ++pos_;
      if (pos_ == buf_.size()) { // nothing left but blanks: the next chunk
        buf_.clear();
        pos_ = 0;
        if (!refill())
          return false;
        continue;
      }
      size_t end = pos_;
      while (end < buf_.size() && !blank(buf_[end]))
        ++end;
      if (end < buf_.size() || at_end_) {
        out = std::string_view(buf_.data() + pos_, end - pos_);
        pos_ = end;
        return true;
      }
      buf_.erase(0, pos_); // a token cut by the chunk's end: keep it, read on
      pos_ = 0;
      at_end_ = !refill();
    }
  }

private:
  bool refill() {
    const size_t n = size_t(std::min<uint64_t>(kStlChunk, in_.remaining()));
    if (n == 0)
      return false;
    const size_t old = buf_.size();
    buf_.resize(old + n);
    if (!in_.read(buf_.data() + old, n))
      fail_io(path_, "read error");
    return true;
  }
  FileReader in_;
  std::string path_;
  std::string buf_;
  size_t pos_ = 0;
  bool at_end_ = false;
};

/// Counts the occurrences of `word` in the file (for ASCII STL: "endloop" = facets), in
/// chunks of 4 MiB; the last word.size() - 1 bytes of each chunk are searched again with
/// the next, so that a word cut by a chunk's end counts ("endloop" cannot overlap itself:
/// no occurrence is counted twice).
uint64_t count_occurrences(const std::string &path, std::string_view word) {
  FileReader in(path);
  std::string buf;
  uint64_t n = 0;
  while (in.remaining() > 0) {
    const size_t keep = std::min(buf.size(), word.size() - 1);
    buf.erase(0, buf.size() - keep);
    const size_t k = size_t(std::min<uint64_t>(kStlChunk, in.remaining()));
    buf.resize(keep + k);
    if (!in.read(buf.data() + keep, k))
      fail_io(path, "read error");
    const std::string_view text(buf);
    for (size_t at = text.find(word); at != text.npos; at = text.find(word, at + word.size()))
      ++n;
  }
  return n;
}

/// A coordinate of ASCII STL: a plain decimal with from_chars (correctly rounded to float,
/// as strtof), anything else ('+', inf, hex, ...) as parse_float reads it.
bool stl_float(std::string_view c, float &x) {
  if (plain_decimal(c.data(), c.data() + c.size())) {
    const auto r = std::from_chars(c.data(), c.data() + c.size(), x);
    if (r.ec == std::errc() && r.ptr == c.data() + c.size())
      return true;
  }
  return parse_float(std::string(c), x);
}

/// ASCII STL, read here rather than by vcglib (whose reader leaks its FILE on a malformed
/// vertex line, found by fuzzing): every "outer loop" ... "endloop" must hold exactly three
/// "vertex x y z" lines; everything else (solid names, facet normals) is skipped. 3 new
/// vertices per facet, in file order. The size check sees the facet count ("endloop"
/// keywords) before the mesh is allocated.
Mesh read_ascii_stl(const std::string &path, const SizeCheck &check) {
  const uint64_t facets = count_occurrences(path, "endloop");
  // Half a vertex per facet, as for binary STL (see load_stl). The text is read in chunks
  // (StlTokens), twice: once to count, once to read.
  run_size_check(check, path, facets / 2, facets);
  Mesh mesh;
  mesh.positions.reserve(static_cast<size_t>(9 * facets));
  mesh.triangles.reserve(static_cast<size_t>(3 * facets));
  size_t in_loop = 0, facet = 0;
  bool looping = false;
  StlTokens tokens(path);
  std::string_view tok;
  while (tokens.next(tok)) {
    if (tok == "loop") {
      looping = true;
      in_loop = 0;
    } else if (tok == "vertex") {
      float v[3];
      std::string_view c;
      for (float &x : v)
        if (!looping || !tokens.next(c) || !stl_float(c, x))
          fail(path, "malformed vertex in ASCII STL facet " + num(facet));
      mesh.positions.insert(mesh.positions.end(), v, v + 3);
      ++in_loop;
    } else if (tok == "endloop") {
      if (!looping || in_loop != 3)
        fail(path,
             "ASCII STL facet " + num(facet) + " has " + num(in_loop) + " vertices (3 expected)");
      const uint32_t first = static_cast<uint32_t>(mesh.positions.size() / 3 - 3);
      mesh.triangles.insert(mesh.triangles.end(), {first, first + 1, first + 2});
      looping = false;
      ++facet;
    }
  }
  if (looping)
    fail(path, "ASCII STL ends inside facet " + num(facet));
  return mesh;
}

} // namespace

Mesh load_stl(const std::string &path, LoadReport &report, const SizeCheck &check) {
  const StlKind kind = classify_stl(path);
  report.text = !kind.binary;
  // Identical corners are welded below: a closed mesh keeps about one vertex per two
  // facets, which is what the encoder will hold (the 3 corners per facet read first cost
  // less than its per-vertex structures).
  if (kind.binary)
    run_size_check(check, path, kind.facets / 2, kind.facets);
  bool colored = false;
  Mesh mesh =
      kind.binary ? read_binary_stl(path, kind.facets, colored) : read_ascii_stl(path, check);
  if (colored)
    add_unique(report.ignored_attributes, "colors");
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    check_finite(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2], v,
                 path, true);
  report.file_vertices = mesh.vertex_count();
  report.file_faces = mesh.triangle_count();
  report.welded_vertices = weld_identical(mesh);
  return mesh;
}

/// ASCII STL; the facet normal is the normalized cross product (0 for a degenerate facet).
void write_stl_ascii(TextFileWriter &out, const Mesh &mesh) {
  std::string &s = out.text();
  s += "solid pomar\n";
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const float *p[3];
    for (int k = 0; k < 3; ++k)
      p[k] = &mesh.positions[3 * mesh.triangles[3 * t + k]];
    double e1[3], e2[3], n[3];
    for (int i = 0; i < 3; ++i)
      e1[i] = double(p[1][i]) - p[0][i], e2[i] = double(p[2][i]) - p[0][i];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    s += "  facet normal";
    for (double c : n) {
      s += ' ';
      append_float_sci(s, len > 0 ? float(c / len) : 0.0f);
    }
    s += "\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      s += "      vertex";
      for (int i = 0; i < 3; ++i) {
        s += ' ';
        append_float_sci(s, p[k][i]);
      }
      s += '\n';
    }
    s += "    endloop\n  endfacet\n";
    out.done();
  }
  s += "endsolid pomar\n";
}

void save_stl_binary(const std::string &path, const Mesh &mesh) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  // The bytes vcglib's exporter writes (its "VCG" header, the facet count, per facet the
  // normal as vcglib computes it in float, the corners and a zero attribute word), from the
  // flat arrays in large chunks instead of through a vcglib copy of the mesh.
  char header[80];
  std::memset(header, ' ', sizeof header);
  std::memcpy(header, "VCG", 3);
  const uint64_t nf = mesh.triangle_count();
  const int32_t count = static_cast<int32_t>(nf); // at most INT_MAX (check_mesh_for_save)
  ChunkedFileWriter out(path, 84 + 50 * nf);
  out.put(header, sizeof header);
  out.put(&count, 4);
  for (uint64_t t = 0; t < nf; ++t) {
    const float *p[3];
    for (int k = 0; k < 3; ++k)
      p[k] = &mesh.positions[3 * size_t(mesh.triangles[3 * t + k])];
    // vcg::TriangleNormal(f).Normalize(): (p1 - p0) ^ (p2 - p0), each divided by the float
    // norm when it is positive.
    const float a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const float b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    float n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    const float norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (norm > 0.0f)
      n[0] /= norm, n[1] /= norm, n[2] /= norm;
    char *record = out.reserve(50);
    std::memcpy(record, n, 12);
    for (int k = 0; k < 3; ++k)
      std::memcpy(record + 12 + 12 * k, p[k], 12);
    record[48] = record[49] = 0;
  }
  out.commit();
#else
  save_stl_binary_vcg(path, mesh);
#endif
}

void save_stl_binary_vcg(const std::string &path, const Mesh &mesh) {
  IoMesh m;
  to_vcg(mesh, m);
  TempFile tmp(path);
  const uint64_t nf = mesh.triangle_count();
  using Exporter = vcg::tri::io::ExporterSTL<IoMesh>;
  errno = 0;
  const int err = Exporter::Save(m, tmp.path().c_str(), true);
  if (err != 0)
    fail_io(path, "cannot write: " + vcg_message<Exporter>(err, 3) + errno_suffix());
  check_written_size(tmp.path(), 84 + 50 * nf, path);
  tmp.commit(true);
}

} // namespace pomar::io
