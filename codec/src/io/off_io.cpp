// OFF: the token stream vcglib's importer reads, walked first (see io_common.h), then the
// import with count checks; writing formatted here.
#include "io/io_common.h"

#include <cstdlib>

#include <pomar/vcg_adapter.h>

#include <wrap/io_trimesh/import_off.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>

namespace pomar::io {
namespace {

/// The token stream of vcglib's ImporterOFF, line by line: lines that are empty or start
/// with '#' or CR are skipped (except the last line of the file), tokens are separated by
/// spaces and tabs. The structure walk must see exactly what vcglib will see.
class OffLines {
public:
  explicit OffLines(const std::string &path) : in_(path) {
    if (!in_)
      fail_io(path, "cannot open: " + errno_text(errno));
  }
  bool failed() const { return in_.fail(); }

  /// Tokens of the next line (empty at the end of the file).
  const std::vector<std::string> &next() {
    std::string line;
    do
      std::getline(in_, line);
    while ((line.empty() || line[0] == '#' || line[0] == '\r') && !in_.eof());
    tokens_.clear();
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
        ++i;
      if (i == line.size())
        break;
      const size_t j = std::min(line.find_first_of(" \t", i), line.size());
      tokens_.push_back(line.substr(i, j - i));
      i = j;
    }
    return tokens_;
  }

private:
  std::ifstream in_;
  std::vector<std::string> tokens_;
};

/// Header of an OFF file as vcglib interprets it.
struct OffHeader {
  bool normals = false, colors = false, texcoords = false;
  uint64_t vertices = 0, faces = 0;
};

struct OffLayout {
  size_t vertices = 0, faces = 0, triangles = 0, polygons = 0;
  bool alpha = false; // a vertex colour has 4 values (RGBA)
};

/// Walks an OFF file the way ImporterOFF reads it, refusing what it would read out of
/// bounds (missing faces, bad indices) or silently misread (garbage numbers).
class OffWalker {
public:
  OffWalker(const std::string &path, const SizeCheck &check)
      : path_(path), check_(check), lines_(path) {}

  OffLayout run() {
    const OffHeader h = header();
    run_size_check(check_, path_, h.vertices, h.faces);
    tokens_ = lines_.next();
    k_ = 0;
    for (uint64_t i = 0; i < h.vertices; ++i)
      vertex(h, i);
    OffLayout out;
    out.alpha = alpha_;
    out.vertices = static_cast<size_t>(h.vertices);
    out.faces = static_cast<size_t>(h.faces);
    for (uint64_t f = 0; f < h.faces; ++f) {
      const size_t n = face(f, h.vertices);
      out.triangles += n - 2;
      out.polygons += n > 3;
    }
    return out;
  }

private:
  /// "[ST][C][N]OFF" and the counts line (or the counts on the keyword's line).
  OffHeader header() {
    std::vector<std::string> t = lines_.next();
    const size_t at = t.empty() ? std::string::npos : t[0].rfind("OFF");
    if (at == std::string::npos)
      fail(path_, "not an OFF file (no OFF keyword)");
    OffHeader h;
    const std::string prefix = t[0].substr(0, at);
    h.colors = prefix.find('C') != std::string::npos;
    h.normals = prefix.find('N') != std::string::npos;
    h.texcoords = prefix.find("ST") != std::string::npos;
    if (prefix.find_first_of("4n") != std::string::npos)
      fail(path_, "4OFF/nOFF (homogeneous or n-dimensional) files are not supported");
    if (t.size() == 1)
      t = lines_.next();
    else
      t.erase(t.begin());
    if (t.size() < 3 || !parse_count(strip_cr(t[0]), INT_MAX, h.vertices) ||
        !parse_count(strip_cr(t[1]), INT_MAX, h.faces))
      fail(path_, "bad OFF counts line (expected: vertices faces edges)");
    return h;
  }

  static std::string strip_cr(std::string s) {
    while (!s.empty() && s.back() == '\r')
      s.pop_back();
    return s;
  }

  /// Next token, continuing on the next line when the current one is used up.
  const std::string &token(const char *what, uint64_t index) {
    if (k_ == tokens_.size()) {
      tokens_ = lines_.next();
      k_ = 0;
      if (tokens_.empty())
        fail(path_, std::string("truncated OFF file (") + what + " " + num(index) + ")");
    }
    return tokens_[k_++];
  }

  void vertex(const OffHeader &h, uint64_t i) {
    float p[3];
    for (float &c : p)
      if (!parse_float(strip_cr(token("vertex", i)), c))
        fail(path_, "OFF vertex " + num(i) + " has a bad coordinate '" + tokens_[k_ - 1] + "'");
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      fail(path_,
           "vertex " + num(i) + " has a non-finite coordinate " + point_text(p[0], p[1], p[2]));
    for (int j = 0; h.normals && j < 3; ++j)
      token("vertex normal", i);
    if (h.colors) { // the rest of the line, minus texture coordinates
      const long n = long(tokens_.size()) - long(k_) - (h.texcoords ? 2 : 0);
      if (n < 0 || n > 4)
        fail(path_, "OFF vertex " + num(i) + " has a bad color");
      if (n == 1) {
        // One value is an index into vcglib's 148-entry colour map, which its importer
        // reads without a range check (found by fuzz_mesh_readers): digits below 148 only.
        const std::string index = strip_cr(tokens_[k_]);
        if (index.empty() || index.size() > 3 ||
            index.find_first_not_of("0123456789") != std::string::npos || std::stoi(index) >= 148)
          fail(path_,
               "OFF vertex " + num(i) + " has a colour map index '" + index + "' outside 0..147");
      }
      if ((n == 3 || n == 4) && tokens_[k_].find('.') != std::string::npos)
        for (long j = 0; j < n; ++j) {
          // vcglib reads RGB(A) with a dot in the first value as floats (atof) and converts
          // each to a byte as (unsigned char)(x * 255): undefined outside (-1, 256) (found
          // by fuzz_mesh_readers): 0..1, as OFF colours in floats are.
          const float x = static_cast<float>(std::atof(tokens_[k_ + size_t(j)].c_str()));
          if (!(x * 255.0f > -1.0f && x * 255.0f < 256.0f))
            fail(path_, "OFF vertex " + num(i) + " has a colour component '" +
                            strip_cr(tokens_[k_ + size_t(j)]) + "' outside 0..1");
        }
      k_ += static_cast<size_t>(n);
      alpha_ |= n == 4;
    }
    for (int j = 0; h.texcoords && j < 2; ++j)
      token("vertex texture coordinate", i);
  }

  /// One face line: corner count, then indices (possibly continued on further lines).
  size_t face(uint64_t f, uint64_t vertices) {
    if (lines_.failed())
      fail(path_, "truncated OFF file (face " + num(f) + ")");
    tokens_ = lines_.next();
    if (tokens_.empty())
      fail(path_, "truncated OFF file (face " + num(f) + ")");
    uint64_t n = 0;
    if (!parse_count(strip_cr(tokens_[0]), INT_MAX, n) || n < 3)
      fail(path_, "OFF face " + num(f) + " has a bad vertex count '" + tokens_[0] + "'");
    k_ = 1;
    for (uint64_t j = 0; j < n; ++j) {
      uint64_t v = 0;
      const std::string t = strip_cr(token("face", f));
      if (!parse_count(t, UINT32_MAX, v) || v >= vertices)
        fail(path_, "OFF face " + num(f) + " references vertex '" + t + "' but there are " +
                        num(vertices) + " vertices");
    }
    return static_cast<size_t>(n);
  }

  std::string path_;
  const SizeCheck &check_;
  OffLines lines_;
  std::vector<std::string> tokens_;
  size_t k_ = 0;
  bool alpha_ = false; // a vertex colour of 4 values seen
};

using OffImporter = vcg::tri::io::ImporterOFF<IoMesh>;

/// The lines of a small file held in memory, split at '\n', without the '\r' of a CRLF
/// line end (vcglib's line reader reads "1 2 3\r" as "1 2 3": the '\r' ends the last
/// number for atof and atoi, and a line of only "\r" is blank).
class TextLines {
public:
  explicit TextLines(std::string text) : text_(std::move(text)) {}
  /// The next line in [b, e); false at the end of the text.
  bool next(const char *&b, const char *&e) {
    if (pos_ >= text_.size())
      return false;
    const size_t end = std::min(text_.find('\n', pos_), text_.size());
    b = text_.data() + pos_;
    e = text_.data() + end;
    if (e != b && e[-1] == '\r')
      --e;
    pos_ = end + 1;
    return true;
  }
  /// The next line that is not blank or a comment (what vcglib's line reader skips: an
  /// empty line, one of only "\r", one starting with '#').
  bool next_data(const char *&b, const char *&e) {
    while (next(b, e))
      if (b != e && *b != '#')
        return true;
    return false;
  }

private:
  std::string text_;
  size_t pos_ = 0;
};

/// Splits [b, e) at spaces and tabs into at most `n` tokens; false if the line has another
/// number of tokens (or a character vcglib's line reader treats specially: '#', '\r').
bool tokens_of(const char *b, const char *e, size_t n, std::pair<const char *, const char *> *out) {
  size_t k = 0;
  while (b != e) {
    if (*b == ' ' || *b == '\t') {
      ++b;
      continue;
    }
    const char *t = b;
    while (b != e && *b != ' ' && *b != '\t') {
      if (*b == '#' || *b == '\r')
        return false;
      ++b;
    }
    if (k == n)
      return false;
    out[k++] = {t, b};
  }
  return k == n;
}

bool parse_index(std::pair<const char *, const char *> t, uint64_t max, uint64_t &v) {
  return parse_digits(t.first, t.second, max, v);
}

/// The common case read straight into the flat arrays: "OFF", the counts line, one vertex
/// of 3 plain decimal coordinates a line (atof then float, as vcglib reads them; all
/// finite), one "3 a b c" triangle a line (distinct indices in range), LF or CRLF line
/// ends, blank and comment lines between them, nothing else (no other CR, no colour or
/// normal, nothing after the faces but one empty line). Returns false for anything else, and the
/// walk and vcglib read the file; files over 256 MiB are left to them too (this path holds
/// the text in memory).
bool read_simple_off(const std::string &path, const SizeCheck &check, Mesh &out,
                     LoadReport &report) {
  FileReader in(path);
  if (in.remaining() > (uint64_t(256) << 20))
    return false;
  std::string text(in.remaining(), '\0');
  if (!in.read(text.data(), text.size()))
    return false;
  TextLines lines(std::move(text));
  const char *b = nullptr, *e = nullptr;
  std::pair<const char *, const char *> t[4];
  uint64_t nv = 0, nf = 0, edges = 0;
  if (!lines.next_data(b, e) || std::string(b, e) != "OFF" || !lines.next_data(b, e) ||
      !tokens_of(b, e, 3, t) || !parse_index(t[0], INT_MAX, nv) ||
      !parse_index(t[1], INT_MAX, nf) || !parse_index(t[2], UINT64_MAX, edges) || nv == 0 ||
      nf == 0)
    return false;
  run_size_check(check, path, nv, nf);
  Mesh mesh;
  mesh.positions.resize(3 * nv);
  for (uint64_t v = 0; v < nv; ++v) {
    if (!lines.next_data(b, e) || !tokens_of(b, e, 3, t))
      return false;
    for (int k = 0; k < 3; ++k) {
      double x = 0;
      if (!plain_decimal(t[k].first, t[k].second))
        return false;
      const auto r = std::from_chars(t[k].first, t[k].second, x);
      float &c = mesh.positions[3 * v + k];
      c = static_cast<float>(x);
      if (r.ec != std::errc() || r.ptr != t[k].second || !std::isfinite(c))
        return false;
    }
  }
  mesh.triangles.resize(3 * nf);
  std::vector<uint8_t> used(nv, 0);
  for (uint64_t f = 0; f < nf; ++f) {
    uint64_t count = 0, v[3];
    if (!lines.next_data(b, e) || !tokens_of(b, e, 4, t) || !parse_index(t[0], 3, count) ||
        count != 3)
      return false;
    for (int k = 0; k < 3; ++k) {
      if (!parse_index(t[k + 1], nv - 1, v[k]))
        return false;
      mesh.triangles[3 * f + k] = static_cast<uint32_t>(v[k]);
      used[v[k]] = 1;
    }
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
      return false;
  }
  if (lines.next(b, e)) // only an empty last line may follow
    if (b != e || lines.next(b, e))
      return false;
  report.file_vertices = nv;
  report.file_faces = nf;
  report.unreferenced_vertices = static_cast<size_t>(std::count(used.begin(), used.end(), 0));
  out = std::move(mesh);
  return true;
}

} // namespace

Mesh load_off(const std::string &path, LoadReport &report, const SizeCheck &check) {
  check_regular_file(path);
  Mesh fast;
  if (read_simple_off(path, check, fast, report))
    return fast;
  const OffLayout layout = OffWalker(path, check).run();
  IoMesh m;
  int mask = 0;
  const int err = guarded(path, [&] { return OffImporter::Open(m, path.c_str(), mask); });
  if (err != OffImporter::NoError)
    fail(path, "OFF import failed: " + vcg_message<OffImporter>(err, 7));
  // Per-vertex colours (COFF) and normals (NOFF) are kept; texture coordinates (STOFF)
  // are not: vcglib's importer announces them without storing them.
  using M = vcg::tri::io::Mask;
  const int kept = mask & (M::IOM_VERTCOLOR | M::IOM_VERTNORMAL);
  add_ignored_from_mask(mask & ~kept, report.ignored_attributes);
  check_counts(m, layout.vertices, layout.triangles, path, "vcglib's OFF importer");
  clear_flags(m); // the importer marks polygon diagonals as faux edges
  check_finite(m, path, false);

  report.file_vertices = layout.vertices;
  report.file_faces = layout.faces;
  report.polygons_triangulated = layout.polygons;
  Mesh mesh = from_vcg(m, &report.unreferenced_vertices, kept, true); // unreferenced kept
  // vcglib's colours are RGBA and from_vcg keeps an alpha only where one is not 255: a file
  // with RGBA colours gives 4 channels whatever their values.
  VertexAttribute *c = mesh.find(AttributeKind::Colour);
  if (layout.alpha && c && c->components == 3) {
    std::vector<uint8_t> rgba(c->colour.size() / 3 * 4, 255);
    for (size_t v = 0; v < c->colour.size() / 3; ++v)
      std::copy(&c->colour[3 * v], &c->colour[3 * v] + 3, &rgba[4 * v]);
    c->colour = std::move(rgba);
    c->components = 4;
  }
  return mesh;
}

void write_off(TextFileWriter &out, const Mesh &mesh) {
  const size_t n = mesh.vertex_count();
  const VertexAttribute *colour = mesh.find(AttributeKind::Colour);
  const VertexAttribute *normal = mesh.find(AttributeKind::Normal);
  if (colour && colour->vertex_count() != n)
    colour = nullptr;
  if (normal && normal->vertex_count() != n)
    normal = nullptr;
  std::string &s = out.text();
  s += std::string(colour ? "C" : "") + (normal ? "N" : "") + "OFF\n" + num(n) + " " +
       num(mesh.triangle_count()) + " 0\n";
  if (!colour && !normal) {
    append_vertices(out, mesh, "");
  } else { // one vertex a line: x y z [nx ny nz] [r g b [a]] (vcglib's importer needs it)
    for (size_t v = 0; v < n; ++v) {
      append_point(s, &mesh.positions[3 * v]);
      if (normal) {
        s += ' ';
        append_point(s, &normal->values[3 * v]);
      }
      for (uint32_t k = 0; colour && k < colour->components; ++k) {
        s += ' ';
        append_uint(s, colour->colour[v * colour->components + k]);
      }
      s += '\n';
      out.done();
    }
  }
  append_triangles(out, mesh, "3 ", 0);
}

} // namespace pomar::io
