// Mesh file I/O: PLY, OFF and ASCII STL through vcglib, OBJ through tinyobjloader, binary
// STL read here (see read_binary_stl for why).
//
// vcglib's importers (MeshLab 2020.09) trust their input: a face index past the vertex
// array, a PLY face with more than 255 corners, a truncated OFF face list or an STL file
// without a line break make them read out of bounds, crash or hang. So before handing a
// file to vcglib we walk its structure ourselves (PLY: header and every element; OFF: the
// same token stream vcglib reads; STL: binary/ASCII detection and size) and reject what
// vcglib would mishandle. After the import we check that vcglib produced exactly the
// vertex and triangle counts the walk predicted. OBJ gets a similar line scan before
// tinyobjloader, which silently skips short faces and does not range-check indices.
//
// Writing: binary PLY and binary STL go through vcglib's exporters into a temporary file
// whose size is checked (the exporters ignore write errors) before it is renamed over the
// destination. ASCII PLY, ASCII STL, OFF and OBJ are formatted here, because vcglib prints
// only 7 significant digits (lossy for float) and its OBJ exporter needs material code.
#include <pomar/mesh_io.h>
#include <pomar/vcg_adapter.h>

#include "io/temp_registry.h"

#include <wrap/io_trimesh/export_ply.h>
#include <wrap/io_trimesh/export_stl.h>
#include <wrap/io_trimesh/import_off.h>
#include <wrap/io_trimesh/import_ply.h>
#include <wrap/io_trimesh/import_stl.h>

#include <tiny_obj_loader.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <istream>
#include <streambuf>
#include <string_view>
#include <system_error>
#include <unordered_map>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace pomar {
namespace {

// ======================================================================================
// Errors, names, numbers
// ======================================================================================

/// Every error message starts with the path of the file concerned.
[[noreturn]] void fail(const std::string &path, const std::string &what) {
  throw Error(path + ": " + what);
}

/// Runs the caller's size check (if any), prefixing its error with the path.
void run_size_check(const SizeCheck &check, const std::string &path, uint64_t vertices,
                    uint64_t faces) {
  if (!check)
    return;
  try {
    check(vertices, faces);
  } catch (const Error &e) {
    fail(path, e.what());
  }
}

std::string errno_text(int e) { return std::generic_category().message(e); }

/// " (<system error>)" if errno is set, for messages after C library calls.
std::string errno_suffix() { return errno ? " (" + errno_text(errno) + ")" : std::string(); }

std::string num(uint64_t v) { return std::to_string(v); }

/// A float with 9 significant digits, which reads back exactly ("%.9g", but
/// locale-independent).
void append_float(std::string &out, float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 9);
  out.append(buf, r.ptr);
}

/// A float in STL's "d.ddddddddE+xx" style with 9 significant digits (reads back exactly).
void append_float_sci(std::string &out, float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific, 8);
  out.append(buf, r.ptr);
}

void append_uint(std::string &out, uint64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

std::string point_text(float x, float y, float z) {
  std::string s = "(";
  append_float(s, x);
  s += ", ";
  append_float(s, y);
  s += ", ";
  append_float(s, z);
  return s + ")";
}

/// Parses a whole token as a non-negative decimal integer no larger than `max`.
bool parse_count(const std::string &token, uint64_t max, uint64_t &value) {
  if (token.empty() || token.size() > 19)
    return false;
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  return r.ec == std::errc() && r.ptr == token.data() + token.size() && value <= max;
}

/// Parses a whole token as a (possibly negative) decimal integer.
bool parse_int(const std::string &token, int64_t &value) {
  const char *begin = token.data(), *end = begin + token.size();
  if (begin != end && *begin == '+')
    ++begin; // from_chars does not take a leading '+'
  const auto r = std::from_chars(begin, end, value);
  return begin != end && r.ec == std::errc() && r.ptr == end;
}

/// Parses a whole token as a decimal float (hex floats are refused: not every reader
/// supports them). Returns false for text that is not a number; NaN/Inf parse.
bool parse_float(const std::string &token, float &value) {
  if (token.empty() || token.find_first_of("xX") != std::string::npos)
    return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtof(token.c_str(), &end);
  return end == token.c_str() + token.size();
}

/// Splits a line at spaces, tabs, CR and LF.
std::vector<std::string> split_ws(const std::string &line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    i = line.find_first_not_of(" \t\r\n", i);
    if (i == std::string::npos)
      break;
    size_t j = line.find_first_of(" \t\r\n", i);
    if (j == std::string::npos)
      j = line.size();
    out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

void add_unique(std::vector<std::string> &list, const char *name) {
  if (std::find(list.begin(), list.end(), name) == list.end())
    list.push_back(name);
}

/// Names the attributes in a vcglib import mask that the codec does not keep.
void add_ignored_from_mask(int mask, std::vector<std::string> &out) {
  using M = vcg::tri::io::Mask;
  if (mask & (M::IOM_VERTNORMAL | M::IOM_FACENORMAL | M::IOM_WEDGNORMAL))
    add_unique(out, "normals");
  if (mask & (M::IOM_VERTCOLOR | M::IOM_FACECOLOR | M::IOM_WEDGCOLOR))
    add_unique(out, "colors");
  if (mask & (M::IOM_VERTTEXCOORD | M::IOM_WEDGTEXCOORD | M::IOM_WEDGTEXMULTI))
    add_unique(out, "texture coordinates");
  if (mask & (M::IOM_VERTQUALITY | M::IOM_FACEQUALITY))
    add_unique(out, "quality");
  if (mask & M::IOM_VERTRADIUS)
    add_unique(out, "radius");
  if (mask & (M::IOM_VERTFLAGS | M::IOM_FACEFLAGS))
    add_unique(out, "flags");
  if (mask & M::IOM_CAMERA)
    add_unique(out, "camera");
  if (mask & M::IOM_EDGEINDEX)
    add_unique(out, "edges");
}

// ======================================================================================
// Formats
// ======================================================================================

enum class Format { Ply, Obj, Off, Stl };

const char *const kSupported = "supported: .ply, .obj, .off, .stl";

/// Lower-case extension of the last path component, with its dot ("" if none).
std::string lower_extension(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return "";
  std::string ext = path.substr(dot);
  for (char &c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Format format_of(const std::string &path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply")
    return Format::Ply;
  if (ext == ".obj")
    return Format::Obj;
  if (ext == ".off")
    return Format::Off;
  if (ext == ".stl")
    return Format::Stl;
  if (ext.empty())
    fail(path, std::string("no file extension to tell the mesh format (") + kSupported + ")");
  fail(path, "unknown mesh file extension '" + ext + "' (" + kSupported + ")");
}

const char *format_name(Format f) {
  switch (f) {
  case Format::Ply: return "ply";
  case Format::Obj: return "obj";
  case Format::Off: return "off";
  case Format::Stl: return "stl";
  }
  return "?";
}

// ======================================================================================
// Files
// ======================================================================================

/// Closes a file descriptor when it goes out of scope.
struct FdGuard {
  int fd;
  explicit FdGuard(int f) : fd(f) {}
  ~FdGuard() {
    if (fd >= 0)
      ::close(fd);
  }
  FdGuard(const FdGuard &) = delete;
  FdGuard &operator=(const FdGuard &) = delete;
};

/// Opens `path` read-only and checks that it is a regular file (the walkers and vcglib
/// each open it again, which a pipe would not survive). Returns the file size.
uint64_t check_regular_file(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    fail(path, "cannot open: " + errno_text(errno));
  FdGuard guard(fd);
  struct stat st;
  if (::fstat(fd, &st) != 0)
    fail(path, "cannot stat: " + errno_text(errno));
  if (S_ISDIR(st.st_mode))
    fail(path, "is a directory");
  if (!S_ISREG(st.st_mode))
    fail(path, "not a regular file");
  return static_cast<uint64_t>(st.st_size);
}

/// Buffered sequential reader over a regular file, used by the PLY structure walk.
class FileReader {
public:
  explicit FileReader(const std::string &path) : path_(path) {
    size_ = check_regular_file(path);
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      fail(path, "cannot open: " + errno_text(errno));
    buf_.resize(1 << 16);
  }
  ~FileReader() { ::close(fd_); }
  FileReader(const FileReader &) = delete;
  FileReader &operator=(const FileReader &) = delete;

  uint64_t pos() const { return pos_; }
  uint64_t remaining() const { return size_ - std::min(pos_, size_); }

  /// Next byte, or -1 at the end of the file.
  int get() {
    if (begin_ == end_ && !fill())
      return -1;
    ++pos_;
    return static_cast<unsigned char>(buf_[begin_++]);
  }

  /// Copies the next n bytes to dst; false if the file ends first.
  bool read(void *dst, size_t n) {
    char *out = static_cast<char *>(dst);
    while (n > 0) {
      if (begin_ == end_ && !fill())
        return false;
      const size_t k = std::min(n, end_ - begin_);
      std::memcpy(out, buf_.data() + begin_, k);
      begin_ += k, pos_ += k, out += k, n -= k;
    }
    return true;
  }

  /// Skips n bytes; false if the file ends first.
  bool skip(uint64_t n) {
    if (n > remaining())
      return false;
    const uint64_t buffered = end_ - begin_;
    if (n <= buffered) {
      begin_ += static_cast<size_t>(n);
    } else {
      if (::lseek(fd_, static_cast<off_t>(pos_ + n), SEEK_SET) < 0)
        fail(path_, "cannot seek: " + errno_text(errno));
      begin_ = end_ = 0;
    }
    pos_ += n;
    return true;
  }

  /// One line without its '\n'; false at the end of the file.
  bool line(std::string &out) {
    out.clear();
    int c = get();
    if (c < 0)
      return false;
    for (; c >= 0 && c != '\n'; c = get())
      out.push_back(static_cast<char>(c));
    return true;
  }

  /// Next whitespace-separated token; false at the end of the file.
  bool token(std::string &out) {
    out.clear();
    int c = get();
    while (c >= 0 && std::isspace(c))
      c = get();
    if (c < 0)
      return false;
    for (; c >= 0 && !std::isspace(c); c = get())
      out.push_back(static_cast<char>(c));
    return true;
  }

private:
  bool fill() {
    for (;;) {
      const ssize_t r = ::read(fd_, buf_.data(), buf_.size());
      if (r < 0 && errno == EINTR)
        continue;
      if (r < 0)
        fail(path_, "cannot read: " + errno_text(errno));
      begin_ = 0, end_ = static_cast<size_t>(r);
      return r > 0;
    }
  }

  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0, pos_ = 0; // pos_: offset of the next byte handed out
  std::vector<char> buf_;
  size_t begin_ = 0, end_ = 0;
};

/// A temporary file in the directory of `target`, removed again unless commit() renamed it
/// over the target.
class TempFile {
public:
  explicit TempFile(const std::string &target) : target_(target) {
    static std::atomic<unsigned> counter{0};
    const size_t slash = target.find_last_of('/');
    dir_ = slash == std::string::npos ? "." : target.substr(0, slash + 1);
    const std::string base = slash == std::string::npos ? target : target.substr(slash + 1);
    if (base.empty())
      fail(target, "not a file name");
    const std::string prefix = slash == std::string::npos ? "" : dir_;
    path_ = prefix + "." + base + ".tmp." + num(static_cast<uint64_t>(::getpid())) + "." +
            num(counter++);
    slot_ = register_temporary(path_); // removed by a signal handler, if installed
  }
  ~TempFile() {
    if (!committed_)
      ::unlink(path_.c_str());
    unregister_temporary(slot_);
  }
  TempFile(const TempFile &) = delete;
  TempFile &operator=(const TempFile &) = delete;

  const std::string &path() const { return path_; }

  /// Renames the temporary file over the target (after fsync'ing it if `sync`, for files
  /// written by somebody else), then syncs the directory entry.
  void commit(bool sync) {
    if (sync)
      sync_file();
    if (::rename(path_.c_str(), target_.c_str()) != 0)
      fail(target_, "cannot rename temporary file into place: " + errno_text(errno));
    committed_ = true;
    unregister_temporary(slot_);
    slot_ = -1;
    const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) { // best effort: the data itself is already on disk
      ::fsync(dfd);
      ::close(dfd);
    }
  }

private:
  void sync_file() {
    const int fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
      fail(target_, "cannot reopen temporary file: " + errno_text(errno));
    FdGuard guard(fd);
    if (::fsync(fd) != 0)
      fail(target_, "fsync failed: " + errno_text(errno));
  }

  std::string target_, dir_, path_;
  bool committed_ = false;
  int slot_ = -1;
};

/// Writes all of data to fd, retrying after signals and short writes.
bool write_all(int fd, const char *data, size_t size) {
  while (size > 0) {
    const ssize_t w = ::write(fd, data, size);
    if (w < 0 && errno == EINTR)
      continue;
    if (w <= 0)
      return false;
    data += w, size -= static_cast<size_t>(w);
  }
  return true;
}

// ======================================================================================
// The vcglib mesh the importers fill
// ======================================================================================

class IoVertex;
class IoEdge;
class IoFace;
struct IoTypes : vcg::UsedTypes<vcg::Use<IoVertex>::AsVertexType, vcg::Use<IoEdge>::AsEdgeType,
                                vcg::Use<IoFace>::AsFaceType> {};
// The normal is only there because ImporterOFF stores the normals of an NOFF file without
// asking whether the vertex type has them (EmptyCore::N() asserts). They are dropped.
class IoVertex
    : public vcg::Vertex<IoTypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::BitFlags> {};
// Edges only so that the PLY importer has somewhere to put an "edge" element: without an
// edge container it asserts. They are dropped.
class IoEdge : public vcg::Edge<IoTypes, vcg::edge::VertexRef, vcg::edge::BitFlags> {};
class IoFace : public vcg::Face<IoTypes, vcg::face::VertexRef, vcg::face::BitFlags> {};
class IoMesh
    : public vcg::tri::TriMesh<std::vector<IoVertex>, std::vector<IoFace>, std::vector<IoEdge>> {};

/// vcglib's message for an importer/exporter code, guarding against its off-by-one
/// tables (codes at the table size, empty entries).
template <class Io>
std::string vcg_message(int code, int table_size) {
  const char *text = code >= 0 && code < table_size ? Io::ErrorMsg(code) : nullptr;
  if (text == nullptr || *text == '\0')
    return "error code " + std::to_string(code);
  return text;
}

/// The PLY importer copies a "flags" property into the bit flags, deleted bits included.
/// Those flags mean something else outside vcglib (whose exporter never writes deleted
/// elements), so they are ignored: every element read is kept.
void clear_flags(IoMesh &m) {
  for (auto &v : m.vert)
    v.Flags() = 0;
  for (auto &f : m.face)
    f.Flags() = 0;
}

/// Throws naming vertex i (STL: and its facet) if a coordinate is NaN or infinite.
void check_finite(float x, float y, float z, size_t i, const std::string &path, bool stl) {
  if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z))
    return;
  const std::string where = stl ? " (facet " + num(i / 3) + ")" : "";
  fail(path, "vertex " + num(i) + where + " has a non-finite coordinate " + point_text(x, y, z));
}

/// Throws naming the first vertex (in file order) with a NaN or infinite coordinate.
void check_finite(const IoMesh &m, const std::string &path, bool stl) {
  for (size_t i = 0; i < m.vert.size(); ++i)
    check_finite(m.vert[i].cP()[0], m.vert[i].cP()[1], m.vert[i].cP()[2], i, path, stl);
}

/// Throws unless vcglib built exactly the vertices and triangles the structure walk saw.
void check_counts(const IoMesh &m, size_t vertices, size_t triangles, const std::string &path,
                  const char *what) {
  if (m.vert.size() == vertices && m.face.size() == triangles)
    return;
  fail(path, std::string(what) + " read " + num(m.vert.size()) + " vertices and " +
                 num(m.face.size()) + " triangles, but the file describes " + num(vertices) +
                 " vertices and " + num(triangles) + " triangles (unsupported property type?)");
}

/// Runs a vcglib call, turning its C++ exceptions (bad_alloc for absurd counts, ...) into
/// pomar::Error.
template <class F>
auto guarded(const std::string &path, F &&call) -> decltype(call()) {
  try {
    return call();
  } catch (const Error &) {
    throw;
  } catch (const std::bad_alloc &) {
    fail(path, "out of memory while reading");
  } catch (const std::exception &e) {
    fail(path, std::string("read failed: ") + e.what());
  }
}

// ======================================================================================
// PLY: header and structure walk
// ======================================================================================

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;       // list items for a list
  bool is_list = false;
  PlyType count_type = PlyType::U8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> props;
  /// The first property with that name, as plylib's FindProp picks it.
  const PlyProperty *find(const char *prop) const {
    for (const auto &p : props)
      if (p.name == prop)
        return &p;
    return nullptr;
  }
};

/// Whether plylib would accept property p for a descriptor with these types: it demands
/// exactly the declared types (no conversion).
bool is_list_of(const PlyProperty *p, PlyType item, PlyType count) {
  return p && p->is_list && p->type == item && p->count_type == count;
}
bool is_scalar_of(const PlyProperty *p, PlyType type) {
  return p && !p->is_list && p->type == type;
}

struct PlyHeader {
  enum Encoding { Ascii, BinaryLittle, BinaryBig } encoding = Ascii;
  std::vector<PlyElement> elements;
};

size_t type_size(PlyType t) {
  switch (t) {
  case PlyType::I8: case PlyType::U8: return 1;
  case PlyType::I16: case PlyType::U16: return 2;
  case PlyType::I32: case PlyType::U32: case PlyType::F32: return 4;
  case PlyType::F64: return 8;
  }
  return 0;
}

/// The type names plylib accepts (classic and sized spellings).
bool parse_ply_type(const std::string &s, PlyType &t) {
  static const struct { const char *a, *b; PlyType t; } names[] = {
      {"char", "int8", PlyType::I8},     {"uchar", "uint8", PlyType::U8},
      {"short", "int16", PlyType::I16},  {"ushort", "uint16", PlyType::U16},
      {"int", "int32", PlyType::I32},    {"uint", "uint32", PlyType::U32},
      {"float", "float32", PlyType::F32}, {"double", "float64", PlyType::F64}};
  for (const auto &n : names)
    if (s == n.a || s == n.b) {
      t = n.t;
      return true;
    }
  return false;
}

std::string base_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

/// vcglib expands "comment TextureFile <name>" into a 255-byte stack buffer, substituting
/// the file's base name for each "<this>"; refuse comments that could overflow it.
void check_texture_comment(const std::string &line, const std::string &path) {
  if (line.find("TextureFile") == std::string::npos)
    return;
  const size_t expansions = static_cast<size_t>(std::count(line.begin(), line.end(), '<'));
  const size_t base = base_name(path).size();
  if (base >= 250 || line.size() + expansions * base >= 250)
    fail(path, "PLY TextureFile comment too long for vcglib");
}

/// Handles one "element" or "property" header line.
void add_ply_declaration(PlyHeader &h, const std::vector<std::string> &tok,
                         const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  if (tok[0] == "element") {
    uint64_t count = 0;
    if (tok.size() < 3 || !parse_count(tok[2], INT_MAX, count))
      bad("bad element line '" + tok[0] + " " + (tok.size() > 1 ? tok[1] : "") + " ...'");
    h.elements.push_back({tok[1], count, {}});
    return;
  }
  if (h.elements.empty())
    bad("property before the first element");
  PlyProperty p;
  const bool list = tok.size() > 1 && tok[1] == "list";
  if (list ? tok.size() < 5 : tok.size() < 3)
    bad("incomplete property line");
  p.is_list = list;
  if (list && !parse_ply_type(tok[2], p.count_type))
    bad("unknown type '" + tok[2] + "'");
  if (!parse_ply_type(tok[list ? 3 : 1], p.type))
    bad("unknown type '" + tok[list ? 3 : 1] + "'");
  p.name = tok[list ? 4 : 2];
  h.elements.back().props.push_back(p);
}

/// Parses the header, leaving `in` at the first data byte.
PlyHeader read_ply_header(FileReader &in, const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  std::string line;
  if (!in.line(line) || line.compare(0, 3, "ply") != 0)
    fail(path, "not a PLY file (no 'ply' magic)");
  PlyHeader h;
  bool have_format = false;
  for (;;) {
    if (!in.line(line))
      bad("no end_header");
    if (line.size() > 500) // plylib reads header lines in 511-byte pieces
      bad("line longer than 500 characters");
    if (line.find('\0') != std::string::npos) // plylib's strtok would stop there
      bad("NUL byte");
    const std::vector<std::string> tok = split_ws(line);
    if (tok.empty())
      bad("empty line");
    if (tok[0] == "comment" || tok[0] == "obj_info") {
      check_texture_comment(line, path);
    } else if (tok[0] == "end_header") {
      break;
    } else if (tok[0] == "format") {
      if (have_format || !h.elements.empty() || tok.size() < 3)
        bad("misplaced or incomplete format line");
      if (tok[1] == "ascii")
        h.encoding = PlyHeader::Ascii;
      else if (tok[1] == "binary_little_endian")
        h.encoding = PlyHeader::BinaryLittle;
      else if (tok[1] == "binary_big_endian")
        h.encoding = PlyHeader::BinaryBig;
      else
        bad("unknown format '" + tok[1] + "'");
      have_format = true;
    } else if (tok[0] == "element" || tok[0] == "property") {
      if (!have_format)
        bad("format line missing before '" + tok[0] + "'");
      add_ply_declaration(h, tok, path);
    } else {
      bad("unexpected keyword '" + tok[0] + "'");
    }
  }
  if (!have_format)
    bad("no format line");
  return h;
}

/// What the walk found; the triangle count is what vcglib's importer will build.
struct PlyLayout {
  size_t vertices = 0;
  size_t faces = 0;     // polygons of the face element, or triangles of the strips
  size_t triangles = 0;
  size_t polygons = 0;  // faces with more than 3 corners
  bool edges = false, camera = false;
};

/// Reads PLY values of any type during the walk (binary in either byte order, or ASCII).
class PlyValues {
public:
  PlyValues(FileReader &in, PlyHeader::Encoding enc, const std::string &path)
      : in_(in), enc_(enc), path_(path) {}

  /// One integer value; false at the end of the file.
  bool integer(PlyType t, int64_t &v) {
    if (t == PlyType::F32 || t == PlyType::F64)
      fail(path_, "PLY list count or vertex index of floating-point type");
    if (enc_ == PlyHeader::Ascii) {
      if (!in_.token(tok_))
        return false;
      if (!parse_int(tok_, v))
        fail(path_, "bad integer '" + tok_ + "' in PLY data");
      return true;
    }
    unsigned char b[4] = {0, 0, 0, 0};
    const size_t n = type_size(t);
    if (!in_.read(b, n))
      return false;
    if (enc_ == PlyHeader::BinaryBig)
      std::reverse(b, b + n);
    v = decode(t, b);
    return true;
  }

  /// Skips `count` values of type t; false at the end of the file.
  bool skip(PlyType t, uint64_t count) {
    if (enc_ != PlyHeader::Ascii)
      return count <= UINT64_MAX / 8 && in_.skip(count * type_size(t));
    for (uint64_t i = 0; i < count; ++i) {
      if (!in_.token(tok_))
        return false;
      check_ascii_number(t);
    }
    return true;
  }

  /// Whether `count` values of type t can still be in the file (a bound, to refuse absurd
  /// list lengths before allocating: binary values take their size, ASCII ones >= 1 byte).
  bool fits(PlyType t, uint64_t count) const {
    const uint64_t bytes = enc_ == PlyHeader::Ascii ? 1 : type_size(t);
    return count <= in_.remaining() / bytes;
  }

  /// Skips one property (scalar or list); false at the end of the file.
  bool skip(const PlyProperty &p) {
    if (!p.is_list)
      return skip(p.type, 1);
    int64_t n = 0;
    if (!integer(p.count_type, n))
      return false;
    if (n < 0)
      fail(path_, "negative PLY list length");
    return skip(p.type, static_cast<uint64_t>(n));
  }

private:
  /// plylib reads ASCII values with fscanf("%d"/"%f"), which stops inside a malformed
  /// token and then reads the rest as the next value. Requiring every token to be a whole
  /// number of the property's kind keeps vcglib's reading aligned with this walk.
  void check_ascii_number(PlyType t) {
    int64_t i = 0;
    float f = 0;
    const bool ok = t == PlyType::F32 || t == PlyType::F64
                        ? tok_.find('(') == std::string::npos && parse_float(tok_, f)
                        : parse_int(tok_, i);
    if (!ok)
      fail(path_, "bad number '" + tok_ + "' in PLY data");
  }

  /// Little-endian bytes (zero-padded to 4) to an integer of type t.
  static int64_t decode(PlyType t, const unsigned char *b) {
    const uint32_t u = b[0] | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
    switch (t) {
    case PlyType::I8: return static_cast<int8_t>(u);
    case PlyType::I16: return static_cast<int16_t>(u);
    case PlyType::I32: return static_cast<int32_t>(u);
    default: return u; // U8, U16, U32
    }
  }

  FileReader &in_;
  PlyHeader::Encoding enc_;
  std::string path_, tok_;
};

/// Walks the rest of the PLY body, validating the connectivity element.
class PlyWalker {
public:
  PlyWalker(FileReader &in, const PlyHeader &h, const std::string &path)
      : in_(in), h_(h), path_(path), values_(in, h.encoding, path) {}

  PlyLayout run() {
    choose_elements();
    for (const PlyElement &e : h_.elements) {
      if (&e == conn_)
        walk(e, e.name == "tristrips");
      else
        skip_element(e);
      layout_.edges |= e.name == "edge" && e.count > 0;
      layout_.camera |= e.name == "camera" && e.count > 0;
    }
    return layout_;
  }

private:
  /// Finds the vertex element and the list vcglib will take faces from, trying the
  /// property types in the order of ImporterPLY::Open. vcglib reads a "face", "tristrips",
  /// "range_grid" or "edge" element even when it registered none of its properties, into
  /// uninitialized memory; such files are refused.
  void choose_elements() {
    const PlyElement *vertex = single("vertex"), *face = single("face"),
                     *strips = single("tristrips"), *edge = single("edge");
    single("camera");
    if (single("range_grid"))
      fail(path_, "PLY range grids (range_grid element) are not supported");
    layout_.vertices = vertex ? static_cast<size_t>(vertex->count) : 0;
    conn_ = face, conn_prop_ = face ? face_index_list(*face) : nullptr;
    if (!conn_prop_ && strips)
      conn_ = strips, conn_prop_ = strips->find("vertex_indices");
    if (conn_ == strips && !is_list_of(conn_prop_, PlyType::I32, PlyType::I32))
      conn_prop_ = nullptr;
    if (!conn_prop_)
      conn_ = nullptr;
    for (const PlyElement *e : {face, strips})
      if (e && e->count > 0 && e != conn_)
        fail(path_, "PLY " + e->name + " element without a vertex index list of a type vcglib reads");
    // plylib cannot byte-swap doubles (SwapDouble() is an assert(0)); these it would store.
    for (const char *name : {"x", "y", "z", "nx", "ny", "nz"})
      if (h_.encoding == PlyHeader::BinaryBig && vertex && is_scalar_of(vertex->find(name), PlyType::F64))
        fail(path_, "big-endian PLY with double vertex data, which vcglib cannot read");
    // plylib reads binary index lists with a one-byte count unless the items are int.
    if (conn_prop_ && h_.encoding != PlyHeader::Ascii && conn_prop_->type != PlyType::I32 &&
        type_size(conn_prop_->count_type) != 1)
      fail(path_, "PLY " + conn_->name + " list with a count wider than a byte and non-int indices, "
                  "which vcglib misreads in binary files");
    if (conn_ && conn_->count > 0 && (!vertex || conn_ < vertex))
      fail(path_, "PLY " + conn_->name + " element comes before the vertex element");
    if (edge && edge->count > 0 &&
        !(is_scalar_of(edge->find("vertex1"), PlyType::I32) && is_scalar_of(edge->find("vertex2"), PlyType::I32)))
      fail(path_, "PLY edge element without int vertex1/vertex2 properties");
  }

  /// The element with that name, or null; refuses a second one (vcglib reads it without
  /// its properties registered).
  const PlyElement *single(const char *name) {
    const PlyElement *found = nullptr;
    for (const PlyElement &e : h_.elements)
      if (e.name == name) {
        if (found)
          fail(path_, std::string("PLY file has two '") + name + "' elements");
        found = &e;
      }
    return found;
  }

  /// The face's index list if its types are among those vcglib reads (FaceDesc 0, 13-24).
  static const PlyProperty *face_index_list(const PlyElement &face) {
    using T = PlyType;
    static const struct { const char *name; T item, count; } kinds[] = {
        {"vertex_indices", T::I32, T::U8},  {"vertex_index", T::I32, T::U8},
        {"vertex_index", T::I32, T::I8},    {"vertex_index", T::I32, T::I32},
        {"vertex_indices", T::I32, T::I8},  {"vertex_indices", T::I32, T::I32},
        {"vertex_indices", T::U32, T::U8},  {"vertex_indices", T::U32, T::I8},
        {"vertex_indices", T::U32, T::I32}, {"vertex_indices", T::U32, T::U16},
        {"vertex_indices", T::I16, T::I8},  {"vertex_indices", T::I16, T::U8},
        {"vertex_indices", T::I16, T::I32}};
    for (const auto &k : kinds)
      if (is_list_of(face.find(k.name), k.item, k.count))
        return face.find(k.name);
    return nullptr;
  }

  [[noreturn]] void truncated(const PlyElement &e, uint64_t item) {
    fail(path_, "truncated PLY file (" + e.name + " " + num(item) + " of " + num(e.count) + ")");
  }

  /// Skips an element; fixed-size binary elements in one seek.
  void skip_element(const PlyElement &e) {
    bool fixed = h_.encoding != PlyHeader::Ascii;
    uint64_t stride = 0;
    for (const auto &p : e.props)
      fixed &= !p.is_list, stride += type_size(p.type);
    if (fixed) {
      if (stride > 0 && (e.count > UINT64_MAX / stride || !in_.skip(e.count * stride)))
        truncated(e, 0);
      return;
    }
    for (uint64_t i = 0; i < e.count; ++i)
      for (const auto &p : e.props)
        if (!skip_unstored(p))
          truncated(e, i);
  }

  /// Skips a property vcglib does not store (for our mesh type: every list except the
  /// face/strip indices). plylib skips a binary list by reading a one-byte count, whatever
  /// the declared count type, into a 512-byte stack buffer, and takes an empty list for the
  /// end of the file (fread of 0 items); refuse lists it would misread.
  bool skip_unstored(const PlyProperty &p) {
    if (!p.is_list || h_.encoding == PlyHeader::Ascii)
      return values_.skip(p);
    if (type_size(p.count_type) != 1)
      fail(path_, "PLY list '" + p.name + "' has a count wider than a byte, which vcglib misreads in binary files");
    int64_t n = 0;
    if (!values_.integer(p.count_type, n))
      return false;
    if (n < 0 || static_cast<uint64_t>(n) * type_size(p.type) > 512)
      fail(path_, "PLY list '" + p.name + "' of " + std::to_string(n) + " items is too long for vcglib");
    if (n == 0)
      fail(path_, "PLY list '" + p.name + "' is empty, which vcglib cannot skip in binary files");
    return values_.skip(p.type, static_cast<uint64_t>(n));
  }

  /// Reads every item of the connectivity element and checks its index list.
  void walk(const PlyElement &e, bool strips) {
    for (uint64_t i = 0; i < e.count; ++i)
      for (const auto &p : e.props) {
        if (&p != conn_prop_) {
          if (!skip_unstored(p))
            truncated(e, i);
          continue;
        }
        int64_t n = 0;
        if (!values_.integer(p.count_type, n))
          truncated(e, i);
        check_length(n, strips, i);
        if (!values_.fits(p.type, static_cast<uint64_t>(n))) // before allocating the list
          truncated(e, i);
        list_.resize(static_cast<size_t>(n));
        for (auto &v : list_)
          if (!values_.integer(p.type, v))
            truncated(e, i);
        if (strips)
          strip(i);
        else
          face(i);
      }
  }

  /// Faces need 3..255 corners (vcglib keeps the count in a byte, the corners in int[512]).
  void check_length(int64_t n, bool strips, uint64_t item) {
    if (strips && (n < 0 || n > INT_MAX))
      fail(path_, "PLY tristrip " + num(item) + " has invalid length " + std::to_string(n));
    if (!strips && (n < 3 || n > 255))
      fail(path_, "PLY face " + num(item) + " has " + std::to_string(n) +
                      " vertices (3 to 255 supported)");
  }

  /// A polygon: all corners must be vertices.
  void face(uint64_t item) {
    for (int64_t v : list_)
      check_index(v, "face", item);
    ++layout_.faces;
    layout_.triangles += list_.size() - 2;
    layout_.polygons += list_.size() > 3;
  }

  /// A triangle strip, -1 restarting it; replays vcglib's loop to count its triangles.
  void strip(uint64_t item) {
    const size_t n = list_.size();
    for (size_t k = 0; k + 2 < n; ++k) {
      check_index(list_[k], "tristrip", item);
      if (list_[k + 2] == -1) {
        k += 2;
        continue;
      }
      check_index(list_[k + 1], "tristrip", item);
      check_index(list_[k + 2], "tristrip", item);
      ++layout_.triangles;
      ++layout_.faces;
    }
  }

  void check_index(int64_t v, const char *what, uint64_t item) {
    if (v < 0 || static_cast<uint64_t>(v) >= layout_.vertices)
      fail(path_, std::string("PLY ") + what + " " + num(item) + " references vertex " +
                      std::to_string(v) + " but there are " + num(layout_.vertices) + " vertices");
  }

  FileReader &in_;
  const PlyHeader &h_;
  std::string path_;
  PlyValues values_;
  const PlyElement *conn_ = nullptr;
  const PlyProperty *conn_prop_ = nullptr;
  std::vector<int64_t> list_;
  PlyLayout layout_;
};

// ======================================================================================
// PLY: loading
// ======================================================================================

using PlyImporter = vcg::tri::io::ImporterPLY<IoMesh>;

/// The count of the first element with that name (0 if none).
uint64_t element_count(const PlyHeader &h, const char *name) {
  for (const PlyElement &e : h.elements)
    if (e.name == name)
      return e.count;
  return 0;
}

Mesh load_ply(const std::string &path, LoadReport &report, const SizeCheck &check) {
  PlyLayout layout;
  {
    FileReader in(path);
    const PlyHeader header = read_ply_header(in, path);
    const uint64_t faces = element_count(header, "face");
    run_size_check(check, path, element_count(header, "vertex"), faces);
    layout = PlyWalker(in, header, path).run();
    if (layout.triangles > faces) // polygons or triangle strips
      run_size_check(check, path, layout.vertices, layout.triangles);
  }
  int file_mask = 0; // what the file has, whatever our mesh type can store
  PlyImporter::LoadMask(path.c_str(), file_mask);
  add_ignored_from_mask(file_mask, report.ignored_attributes);
  if (layout.edges)
    add_unique(report.ignored_attributes, "edges");
  if (layout.camera)
    add_unique(report.ignored_attributes, "camera");

  IoMesh m;
  int mask = 0;
  const int err = guarded(path, [&] { return PlyImporter::Open(m, path.c_str(), mask); });
  if (PlyImporter::ErrorCritical(err))
    fail(path, "PLY import failed: " +
                   vcg_message<PlyImporter>(err, vcg::tri::io::PlyInfo::E_MAXPLYINFOERRORS));
  check_counts(m, layout.vertices, layout.triangles, path, "vcglib's PLY importer");
  clear_flags(m);
  check_finite(m, path, false);

  report.file_vertices = layout.vertices;
  report.file_faces = layout.faces;
  report.polygons_triangulated = layout.polygons;
  return from_vcg(m, &report.unreferenced_vertices, true);
}

// ======================================================================================
// OFF
// ======================================================================================

/// The token stream of vcglib's ImporterOFF, line by line: lines that are empty or start
/// with '#' or CR are skipped (except the last line of the file), tokens are separated by
/// spaces and tabs. The structure walk must see exactly what vcglib will see.
class OffLines {
public:
  explicit OffLines(const std::string &path) : in_(path) {
    if (!in_)
      fail(path, "cannot open: " + errno_text(errno));
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
      fail(path_, "vertex " + num(i) + " has a non-finite coordinate " + point_text(p[0], p[1], p[2]));
    for (int j = 0; h.normals && j < 3; ++j)
      token("vertex normal", i);
    if (h.colors) { // the rest of the line, minus texture coordinates
      const long n = long(tokens_.size()) - long(k_) - (h.texcoords ? 2 : 0);
      if (n < 0 || n > 4)
        fail(path_, "OFF vertex " + num(i) + " has a bad color");
      k_ += static_cast<size_t>(n);
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
};

using OffImporter = vcg::tri::io::ImporterOFF<IoMesh>;

Mesh load_off(const std::string &path, LoadReport &report, const SizeCheck &check) {
  check_regular_file(path);
  const OffLayout layout = OffWalker(path, check).run();
  IoMesh m;
  int mask = 0;
  const int err = guarded(path, [&] { return OffImporter::Open(m, path.c_str(), mask); });
  if (err != OffImporter::NoError)
    fail(path, "OFF import failed: " + vcg_message<OffImporter>(err, 7));
  add_ignored_from_mask(mask, report.ignored_attributes);
  check_counts(m, layout.vertices, layout.triangles, path, "vcglib's OFF importer");
  clear_flags(m); // the importer marks polygon diagonals as faux edges
  check_finite(m, path, false);

  report.file_vertices = layout.vertices;
  report.file_faces = layout.faces;
  report.polygons_triangulated = layout.polygons;
  return from_vcg(m, &report.unreferenced_vertices, true);
}

// ======================================================================================
// STL
// ======================================================================================

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
  const unsigned char *text = std::find_if(head, head + probe, [](unsigned char c) { return !std::isspace(c); });
  const bool solid = head + probe - text >= 5 && std::memcmp(text, "solid", 5) == 0;
  kind.binary = size == expected ||
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

/// Merges vertices with exactly equal coordinates (compared as floats, so -0 equals +0),
/// keeping the first occurrence's position and the order of first occurrences. Returns the
/// number of vertices merged away.
size_t weld_identical(Mesh &mesh) {
  struct Key {
    float x, y, z;
    bool operator==(const Key &o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct Hash {
    size_t operator()(const Key &k) const {
      uint32_t b[3];
      const float c[3] = {k.x + 0.0f, k.y + 0.0f, k.z + 0.0f}; // -0 -> +0
      std::memcpy(b, c, sizeof b);
      return (size_t(b[0]) * 0x9E3779B1u) ^ (size_t(b[1]) * 0x85EBCA77u) ^ (size_t(b[2]) * 0xC2B2AE3Du);
    }
  };
  const size_t n = mesh.vertex_count();
  std::unordered_map<Key, uint32_t, Hash> first;
  first.reserve(n);
  std::vector<uint32_t> remap(n);
  std::vector<float> kept;
  kept.reserve(mesh.positions.size());
  for (size_t i = 0; i < n; ++i) {
    const Key key{mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]};
    const auto ins = first.emplace(key, static_cast<uint32_t>(kept.size() / 3));
    if (ins.second)
      kept.insert(kept.end(), {key.x, key.y, key.z});
    remap[i] = ins.first->second;
  }
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
      const uint32_t bits = b[0] | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
      std::memcpy(&mesh.positions[9 * f + c], &bits, 4);
    }
    for (uint32_t k = 0; k < 3; ++k)
      mesh.triangles[3 * f + k] = static_cast<uint32_t>(3 * f + k);
    colored |= rec[48] != 0 || rec[49] != 0;
  }
  return mesh;
}

/// The tokens of a text separated by spaces, tabs, CR and LF (as split_ws), one at a time,
/// as views into the text: no copy of a file that may be hundreds of megabytes.
class TokenCursor {
public:
  explicit TokenCursor(std::string_view text) : text_(text) {}
  /// The next token; false at the end of the text.
  bool next(std::string_view &out) {
    const size_t begin = text_.find_first_not_of(" \t\r\n", pos_);
    if (begin == std::string_view::npos)
      return false;
    pos_ = std::min(text_.find_first_of(" \t\r\n", begin), text_.size());
    out = text_.substr(begin, pos_ - begin);
    return true;
  }

private:
  std::string_view text_;
  size_t pos_ = 0;
};

/// Counts the occurrences of `word` in `text` (for ASCII STL: "endloop" = facets).
uint64_t count_occurrences(std::string_view text, std::string_view word) {
  uint64_t n = 0;
  for (size_t at = text.find(word); at != text.npos; at = text.find(word, at + word.size()))
    ++n;
  return n;
}

/// ASCII STL, read here rather than by vcglib (whose reader leaks its FILE on a malformed
/// vertex line, found by fuzzing): every "outer loop" ... "endloop" must hold exactly three
/// "vertex x y z" lines; everything else (solid names, facet normals) is skipped. 3 new
/// vertices per facet, in file order. The size check sees the facet count ("endloop"
/// keywords) before the mesh is allocated.
Mesh read_ascii_stl(const std::string &path, const SizeCheck &check) {
  const std::vector<uint8_t> bytes = read_file(path);
  const std::string_view text(reinterpret_cast<const char *>(bytes.data()), bytes.size());
  const uint64_t facets = count_occurrences(text, "endloop");
  // The text (about 250 bytes a facet) stays in memory while the facets are read: counted
  // as one vertex per facet, twice what the welded mesh keeps (binary STL: see load_stl).
  run_size_check(check, path, facets, facets);
  Mesh mesh;
  mesh.positions.reserve(static_cast<size_t>(9 * facets));
  mesh.triangles.reserve(static_cast<size_t>(3 * facets));
  size_t in_loop = 0, facet = 0;
  bool looping = false;
  TokenCursor tokens(text);
  std::string_view tok;
  while (tokens.next(tok)) {
    if (tok == "loop") {
      looping = true;
      in_loop = 0;
    } else if (tok == "vertex") {
      float v[3];
      std::string_view c;
      for (float &x : v)
        if (!looping || !tokens.next(c) || !parse_float(std::string(c), x))
          fail(path, "malformed vertex in ASCII STL facet " + num(facet));
      mesh.positions.insert(mesh.positions.end(), v, v + 3);
      ++in_loop;
    } else if (tok == "endloop") {
      if (!looping || in_loop != 3)
        fail(path, "ASCII STL facet " + num(facet) + " has " + num(in_loop) +
                       " vertices (3 expected)");
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

Mesh load_stl(const std::string &path, LoadReport &report, const SizeCheck &check) {
  const StlKind kind = classify_stl(path);
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
    check_finite(mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2], v, path, true);
  report.file_vertices = mesh.vertex_count();
  report.file_faces = mesh.triangle_count();
  report.welded_vertices = weld_identical(mesh);
  return mesh;
}

// ======================================================================================
// OBJ
// ======================================================================================

/// What a line scan of an OBJ file finds, using tinyobjloader's line rules.
struct ObjScan {
  size_t vertices = 0, faces = 0, triangles = 0, polygons = 0;
  bool normals = false, texcoords = false, colors = false, materials = false;
};

/// Splits at spaces and tabs (tinyobjloader's separators within a line).
std::vector<std::string> split_blanks(const char *p, const char *end) {
  std::vector<std::string> out;
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t'))
      ++p;
    const char *q = p;
    while (q < end && *q != ' ' && *q != '\t')
      ++q;
    if (q > p)
      out.emplace_back(p, q);
    p = q;
  }
  return out;
}

/// Checks one "v" line: three finite decimal coordinates.
void scan_obj_vertex(const std::vector<std::string> &tok, ObjScan &s, size_t line,
                     const std::string &path) {
  const std::string where = "line " + num(line) + ": vertex " + num(s.vertices);
  if (tok.size() < 4)
    fail(path, where + " has fewer than 3 coordinates");
  float p[3];
  for (int i = 0; i < 3; ++i)
    if (!parse_float(tok[i + 1], p[i]))
      fail(path, where + " has a bad coordinate '" + tok[i + 1] + "'");
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    fail(path, where + " has a non-finite coordinate " + point_text(p[0], p[1], p[2]));
  s.colors |= tok.size() >= 7;
  ++s.vertices;
}

/// Checks one "f" line: 3..255 corners (tinyobjloader drops shorter faces silently and
/// stores the corner count in a byte).
void scan_obj_face(const std::vector<std::string> &tok, ObjScan &s, size_t line,
                   const std::string &path) {
  const size_t n = tok.size() - 1;
  if (n < 3 || n > 255)
    fail(path, "line " + num(line) + ": face with " + num(n) + " vertices (3 to 255 supported)");
  ++s.faces;
  s.triangles += n - 2;
  s.polygons += n > 3;
}

/// Scans the lines as tinyobjloader splits them (LF, CRLF or CR; text after a NUL byte is
/// ignored), recording vertices, faces and the attributes that will be dropped.
ObjScan scan_obj(const std::vector<uint8_t> &bytes, const std::string &path) {
  ObjScan s;
  const char *p = reinterpret_cast<const char *>(bytes.data());
  const char *const end = p + bytes.size();
  for (size_t line = 1; p < end; ++line) {
    const char *eol = p;
    while (eol < end && *eol != '\n' && *eol != '\r')
      ++eol;
    const char *stop = std::find(p, eol, '\0');
    const std::vector<std::string> tok = split_blanks(p, stop);
    p = eol + (eol < end && *eol == '\r' && eol + 1 < end && eol[1] == '\n' ? 2 : 1);
    if (tok.empty())
      continue;
    const std::string &key = tok[0];
    if (key == "v")
      scan_obj_vertex(tok, s, line, path);
    else if (key == "f")
      scan_obj_face(tok, s, line, path);
    else if (key == "vn")
      s.normals = true;
    else if (key == "vt")
      s.texcoords = true;
    else if (key == "mtllib" || key == "usemtl")
      s.materials = true;
  }
  return s;
}

/// A read-only std::streambuf over memory, to feed tinyobjloader without a copy.
class MemoryBuffer : public std::streambuf {
public:
  MemoryBuffer(const uint8_t *data, size_t size) {
    char *p = const_cast<char *>(reinterpret_cast<const char *>(data));
    setg(p, p, p + size);
  }
};

std::string first_line(const std::string &s) {
  const std::string line = s.substr(0, s.find('\n'));
  return line.empty() ? "unknown error" : line;
}

/// Fan-triangulates tinyobjloader's faces (corner 0 with each following edge), checking
/// that every index is a vertex. Returns the triangles as flat indices.
std::vector<uint32_t> fan_triangles(const std::vector<tinyobj::shape_t> &shapes, size_t vertices,
                                    const std::string &path) {
  std::vector<uint32_t> tris;
  size_t face = 0;
  for (const auto &shape : shapes) {
    const auto &idx = shape.mesh.indices;
    size_t at = 0;
    for (const unsigned char n : shape.mesh.num_face_vertices) {
      if (n < 3 || at + n > idx.size())
        fail(path, "tinyobjloader returned an inconsistent face " + num(face));
      for (size_t c = 0; c < n; ++c) {
        const int v = idx[at + c].vertex_index;
        if (v < 0 || static_cast<size_t>(v) >= vertices)
          fail(path, "face " + num(face) + " references vertex " + std::to_string(v + 1) +
                         " but there are " + num(vertices) + " vertices");
      }
      for (size_t c = 1; c + 1 < n; ++c)
        tris.insert(tris.end(), {uint32_t(idx[at].vertex_index), uint32_t(idx[at + c].vertex_index),
                                 uint32_t(idx[at + c + 1].vertex_index)});
      at += n;
      ++face;
    }
  }
  return tris;
}

/// Vertices no triangle uses (they are kept).
size_t count_unreferenced(const Mesh &mesh) {
  std::vector<uint8_t> used(mesh.vertex_count(), 0);
  for (uint32_t t : mesh.triangles)
    used[t] = 1;
  return static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
}

Mesh load_obj(const std::string &path, LoadReport &report, const SizeCheck &check) {
  const std::vector<uint8_t> bytes = read_file(path);
  const ObjScan scan = scan_obj(bytes, path);
  run_size_check(check, path, scan.vertices, scan.triangles);

  MemoryBuffer buffer(bytes.data(), bytes.size());
  std::istream stream(&buffer);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  // No material reader (mtllib is ignored), no triangulation (tinyobjloader's own picks a
  // quad diagonal by geometry), no default vertex colors.
  const bool ok = guarded(path, [&] {
    return tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, nullptr, false, false);
  });
  if (!ok)
    fail(path, "OBJ parse error: " + first_line(err));
  if (attrib.vertices.size() != 3 * scan.vertices)
    fail(path, "tinyobjloader read " + num(attrib.vertices.size() / 3) + " vertices but the file has " +
                   num(scan.vertices) + " 'v' lines");
  size_t faces = 0;
  for (const auto &shape : shapes)
    faces += shape.mesh.num_face_vertices.size();
  if (faces != scan.faces)
    fail(path, "tinyobjloader read " + num(faces) + " faces but the file has " + num(scan.faces) + " 'f' lines");

  Mesh mesh;
  mesh.triangles = fan_triangles(shapes, scan.vertices, path);
  if (mesh.triangles.size() != 3 * scan.triangles)
    fail(path, "triangulation produced " + num(mesh.triangles.size() / 3) + " triangles, expected " +
                   num(scan.triangles));
  mesh.positions.assign(attrib.vertices.begin(), attrib.vertices.end());

  report.file_vertices = scan.vertices;
  report.file_faces = scan.faces;
  report.polygons_triangulated = scan.polygons;
  report.unreferenced_vertices = count_unreferenced(mesh);
  if (scan.normals) add_unique(report.ignored_attributes, "normals");
  if (scan.texcoords) add_unique(report.ignored_attributes, "texture coordinates");
  if (scan.colors) add_unique(report.ignored_attributes, "colors");
  if (scan.materials) add_unique(report.ignored_attributes, "materials");
  return mesh;
}

// ======================================================================================
// Writing
// ======================================================================================

/// Refuses meshes that cannot be written (or read back): bad sizes, indices out of range,
/// NaN/Inf, more elements than vcglib's int counters.
void check_mesh_for_save(const Mesh &mesh, const std::string &path) {
  if (mesh.positions.size() % 3 != 0 || mesh.triangles.size() % 3 != 0)
    fail(path, "cannot save: positions and triangles must hold a multiple of 3 values");
  const size_t nv = mesh.vertex_count();
  if (nv > size_t(INT_MAX) || mesh.triangle_count() > size_t(INT_MAX))
    fail(path, "cannot save: more than INT_MAX vertices or triangles");
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    if (mesh.triangles[i] >= nv)
      fail(path, "cannot save: triangle " + num(i / 3) + " references vertex " +
                     num(mesh.triangles[i]) + " but there are " + num(nv) + " vertices");
  for (size_t v = 0; v < nv; ++v) {
    const float *p = &mesh.positions[3 * v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      fail(path, "cannot save: vertex " + num(v) + " has a non-finite coordinate " +
                     point_text(p[0], p[1], p[2]));
  }
}

/// Appends "x y z" with full float precision.
void append_point(std::string &out, const float *p) {
  append_float(out, p[0]);
  out += ' ';
  append_float(out, p[1]);
  out += ' ';
  append_float(out, p[2]);
}

/// Appends the triangles as "<prefix>a b c\n" lines, indices offset by `base`.
void append_triangles(std::string &out, const Mesh &mesh, const char *prefix, uint64_t base) {
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    out += prefix;
    for (int k = 0; k < 3; ++k) {
      if (k)
        out += ' ';
      append_uint(out, mesh.triangles[3 * t + k] + base);
    }
    out += '\n';
  }
}

void append_vertices(std::string &out, const Mesh &mesh, const char *prefix) {
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += prefix;
    append_point(out, &mesh.positions[3 * v]);
    out += '\n';
  }
}

std::string ply_ascii_text(const Mesh &mesh) {
  std::string s = "ply\nformat ascii 1.0\ncomment pomar\nelement vertex " + num(mesh.vertex_count()) +
                  "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                  num(mesh.triangle_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  append_vertices(s, mesh, "");
  append_triangles(s, mesh, "3 ", 0);
  return s;
}

std::string off_text(const Mesh &mesh) {
  std::string s = "OFF\n" + num(mesh.vertex_count()) + " " + num(mesh.triangle_count()) + " 0\n";
  append_vertices(s, mesh, "");
  append_triangles(s, mesh, "3 ", 0);
  return s;
}

std::string obj_text(const Mesh &mesh) {
  std::string s = "# pomar\n";
  append_vertices(s, mesh, "v ");
  append_triangles(s, mesh, "f ", 1);
  return s;
}

/// ASCII STL; the facet normal is the normalized cross product (0 for a degenerate facet).
std::string stl_ascii_text(const Mesh &mesh) {
  std::string s = "solid pomar\n";
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
  }
  return s + "endsolid pomar\n";
}

/// Size of the header of a PLY file written by vcglib ("...end_header\n").
uint64_t ply_header_size(const std::string &file, const std::string &target) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  uint64_t size = 0;
  while (size < 65536 && std::getline(in, line)) {
    size += line.size() + 1;
    if (line == "end_header")
      return size;
  }
  fail(target, "vcglib wrote a PLY file without end_header");
}

/// Checks that a file written by a vcglib exporter has the expected size: the exporters
/// do not report failed writes (full disk), so a short file would otherwise go unnoticed.
void check_written_size(const std::string &file, uint64_t expected, const std::string &target) {
  struct stat st;
  if (::stat(file.c_str(), &st) != 0)
    fail(target, "cannot stat temporary file: " + errno_text(errno));
  if (static_cast<uint64_t>(st.st_size) != expected)
    fail(target, "short write (" + num(uint64_t(st.st_size)) + " of " + num(expected) +
                     " bytes; disk full?)");
}

/// Binary PLY or binary STL through vcglib's exporter, via a temporary file.
void save_with_vcg(const std::string &path, const Mesh &mesh, Format format) {
  IoMesh m;
  to_vcg(mesh, m);
  TempFile tmp(path);
  const uint64_t nv = mesh.vertex_count(), nf = mesh.triangle_count();
  if (format == Format::Ply) {
    using Exporter = vcg::tri::io::ExporterPLY<IoMesh>;
    errno = 0;
    const int err = Exporter::Save(m, tmp.path().c_str(), true);
    if (err != 0)
      fail(path, "cannot write: " + vcg_message<Exporter>(err, vcg::tri::io::PlyInfo::E_MAXPLYINFOERRORS) +
                     errno_suffix());
    check_written_size(tmp.path(), ply_header_size(tmp.path(), path) + 12 * nv + 13 * nf, path);
  } else {
    using Exporter = vcg::tri::io::ExporterSTL<IoMesh>;
    errno = 0;
    const int err = Exporter::Save(m, tmp.path().c_str(), true);
    if (err != 0)
      fail(path, "cannot write: " + vcg_message<Exporter>(err, 3) + errno_suffix());
    check_written_size(tmp.path(), 84 + 50 * nf, path);
  }
  tmp.commit(true);
}

} // namespace

// ======================================================================================
// Public API
// ======================================================================================

std::vector<uint8_t> read_file(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    fail(path, "cannot open: " + errno_text(errno));
  FdGuard guard(fd);
  struct stat st;
  const bool have_stat = ::fstat(fd, &st) == 0;
  if (have_stat && S_ISDIR(st.st_mode))
    fail(path, "is a directory");
  // A regular file is read into a buffer of its size (+1 to see the end): growing by
  // doubling would briefly hold 1.5 times a large file.
  std::vector<uint8_t> data;
  if (have_stat && S_ISREG(st.st_mode))
    data.resize(static_cast<size_t>(st.st_size) + 1);
  size_t used = 0;
  for (;;) {
    if (used == data.size())
      data.resize(std::max<size_t>(data.size() * 2, used + 65536));
    const ssize_t r = ::read(fd, data.data() + used, data.size() - used);
    if (r < 0 && errno == EINTR)
      continue;
    if (r < 0)
      fail(path, "cannot read: " + errno_text(errno));
    if (r == 0)
      break;
    used += static_cast<size_t>(r);
  }
  data.resize(used);
  if (data.capacity() - used > used / 8) // grown by doubling (not a regular file)
    data.shrink_to_fit();
  return data;
}

void write_file_atomic(const std::string &path, const void *data, size_t size) {
  TempFile tmp(path);
  const int fd = ::open(tmp.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
    fail(path, "cannot create temporary file '" + tmp.path() + "': " + errno_text(errno));
  FdGuard guard(fd);
  if (!write_all(fd, static_cast<const char *>(data), size))
    fail(path, "cannot write: " + errno_text(errno));
  if (::fsync(fd) != 0)
    fail(path, "fsync failed: " + errno_text(errno));
  guard.fd = -1;
  if (::close(fd) != 0)
    fail(path, "cannot write (close): " + errno_text(errno));
  tmp.commit(false);
}

Mesh load_mesh(const std::string &path, LoadReport *report, const SizeCheck &size_check) {
  const Format format = format_of(path);
  LoadReport local;
  LoadReport &r = report ? *report : local;
  r = LoadReport();
  r.format = format_name(format);
  Mesh mesh;
  switch (format) {
  case Format::Ply:
    mesh = load_ply(path, r, size_check);
    break;
  case Format::Off:
    mesh = load_off(path, r, size_check);
    break;
  case Format::Stl:
    mesh = load_stl(path, r, size_check);
    break;
  case Format::Obj:
    mesh = load_obj(path, r, size_check);
    break;
  }
  if (mesh.triangles.empty())
    fail(path, "contains no triangles");
  return mesh;
}

void save_mesh(const std::string &path, const Mesh &mesh, bool binary) {
  const Format format = format_of(path);
  check_mesh_for_save(mesh, path);
  std::string text;
  switch (format) {
  case Format::Ply:
    if (binary)
      return save_with_vcg(path, mesh, format);
    text = ply_ascii_text(mesh);
    break;
  case Format::Stl:
    if (binary)
      return save_with_vcg(path, mesh, format);
    text = stl_ascii_text(mesh);
    break;
  case Format::Off: text = off_text(mesh); break;
  case Format::Obj: text = obj_text(mesh); break;
  }
  write_file_atomic(path, text.data(), text.size());
}

} // namespace pomar
