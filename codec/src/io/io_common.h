// Internal to pomar_io: what the per-format readers and writers (ply_*.cpp, off_io.cpp,
// stl_io.cpp, obj_io.cpp) share: error messages that start with the path, number
// parsing and printing, file handles, temporary files, and the vcglib mesh the importers
// fill. The public API is <pomar/mesh_io.h>; mesh_io.cpp picks the format.
//
// vcglib's importers (MeshLab 2020.09) trust their input: a face index past the vertex
// array, a PLY face with more than 255 corners, a truncated OFF face list or an STL file
// without a line break make them read out of bounds, crash or hang. So before handing a
// file to vcglib each reader walks its structure itself (PLY: header and every element;
// OFF: the same token stream vcglib reads; STL: binary/ASCII detection and size) and
// rejects what vcglib would mishandle. After the import it checks that vcglib produced
// exactly the vertex and triangle counts the walk predicted. OBJ gets a similar line scan
// before tinyobjloader, which silently skips short faces and does not range-check indices.
#pragma once

#include <pomar/mesh_io.h>

#include "io/temp_registry.h"

#include <vcg/complex/complex.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace pomar::io {

// ---- Errors, names, numbers (io_common.cpp) ----

/// Throws pomar::Error("<path>: <what>") of `kind` naming `path`: every error message
/// starts with the path of the file concerned.
[[noreturn]] void fail(Error::Kind kind, const std::string &path, const std::string &what);
/// fail() for a file whose content cannot be used (Error::Kind::InvalidMesh).
[[noreturn]] void fail(const std::string &path, const std::string &what);
/// fail() for a file that cannot be opened, read or written (Error::Kind::Io).
[[noreturn]] void fail_io(const std::string &path, const std::string &what);
/// Runs the caller's size check (if any), prefixing its error with the path.
void run_size_check(const SizeCheck &check, const std::string &path, uint64_t vertices,
                    uint64_t faces);
std::string errno_text(int e);
/// " (<system error>)" if errno is set, for messages after C library calls.
std::string errno_suffix();
std::string num(uint64_t v);
/// A float with 9 significant digits, which reads back exactly ("%.9g", but
/// locale-independent).
void append_float(std::string &out, float v);
/// A float in STL's "d.ddddddddE+xx" style with 9 significant digits (reads back exactly).
void append_float_sci(std::string &out, float v);
void append_uint(std::string &out, uint64_t v);
std::string point_text(float x, float y, float z);
/// Parses a whole token as a non-negative decimal integer no larger than `max`.
bool parse_count(const std::string &token, uint64_t max, uint64_t &value);
/// Parses a whole token as a (possibly negative) decimal integer.
bool parse_int(const std::string &token, int64_t &value);
/// Parses a whole token as a decimal float (hex floats are refused: not every reader
/// supports them). Returns false for text that is not a number; NaN/Inf parse.
bool parse_float(const std::string &token, float &value);
/// Whether [b, e) is a plain decimal number, [-]digits[.digits][(e|E)[+-]digits] (at least
/// one digit before the exponent): what the fast paths parse with from_chars. For such
/// text from_chars rounds as strtof/strtod (and so vcglib's fscanf/atof) do; anything else
/// ('+', hex, inf, nan, ...) is left to the general readers.
bool plain_decimal(const char *b, const char *e);
/// Parses [b, e) as a plain unsigned decimal integer (digits only: no sign, no space) of
/// at most `max`: what the fast paths read counts and vertex indices with.
bool parse_digits(const char *b, const char *e, uint64_t max, uint64_t &value);
/// Splits a line at spaces, tabs, CR and LF.
std::vector<std::string> split_ws(const std::string &line);
void add_unique(std::vector<std::string> &list, const char *name);
/// Names the attributes in a vcglib import mask that the codec does not keep.
void add_ignored_from_mask(int mask, std::vector<std::string> &out);

// ---- Files ----

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
uint64_t check_regular_file(const std::string &path);

/// Buffered sequential reader over a regular file, used by the PLY structure walk.
class FileReader {
public:
  explicit FileReader(const std::string &path) : path_(path) {
    size_ = check_regular_file(path);
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      fail_io(path, "cannot open: " + errno_text(errno));
    buf_.resize(1 << 16);
    for (int c = 0; c < 256; ++c) // (std::isspace, looked up once: the locale's spaces)
      space_[c] = std::isspace(c) != 0;
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
        fail_io(path_, "cannot seek: " + errno_text(errno));
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

  /// Next whitespace-separated token, the one whitespace byte after it consumed too;
  /// false at the end of the file. (Scanned in the buffer, appended a run at a time.)
  bool token(std::string &out) {
    out.clear();
    for (;;) { // skip whitespace
      while (begin_ < end_ && is_space(buf_[begin_]))
        ++begin_, ++pos_;
      if (begin_ < end_)
        break;
      if (!fill())
        return false;
    }
    for (;;) {
      size_t i = begin_;
      while (i < end_ && !is_space(buf_[i]))
        ++i;
      out.append(buf_.data() + begin_, i - begin_);
      pos_ += i - begin_;
      begin_ = i;
      if (begin_ < end_) { // the whitespace byte that ends it
        ++begin_, ++pos_;
        return true;
      }
      if (!fill())
        return true;
    }
  }

private:
  bool fill() {
    for (;;) {
      const ssize_t r = ::read(fd_, buf_.data(), buf_.size());
      if (r < 0 && errno == EINTR)
        continue;
      if (r < 0)
        fail_io(path_, "cannot read: " + errno_text(errno));
      begin_ = 0, end_ = static_cast<size_t>(r);
      return r > 0;
    }
  }

  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0, pos_ = 0; // pos_: offset of the next byte handed out
  std::vector<char> buf_;
  size_t begin_ = 0, end_ = 0;
  bool space_[256];
  bool is_space(char c) const { return space_[static_cast<unsigned char>(c)]; }
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
      fail_io(target, "not a file name");
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
      fail_io(target_, "cannot rename temporary file into place: " + errno_text(errno));
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
      fail_io(target_, "cannot reopen temporary file: " + errno_text(errno));
    FdGuard guard(fd);
    if (::fsync(fd) != 0)
      fail_io(target_, "fsync failed: " + errno_text(errno));
  }

  std::string target_, dir_, path_;
  bool committed_ = false;
  int slot_ = -1;
};

/// Writes all of data to fd, retrying after signals and short writes.
bool write_all(int fd, const char *data, size_t size);

/// The temporary file behind an atomic write (write_file_atomic, ChunkedFileWriter,
/// TextFileWriter): write() appends to it, commit() fsyncs and closes it and renames it over
/// the target. Every failure is an I/O error naming the target; destroyed without
/// commit(), it removes the temporary file, so a failed write never leaves part of a file
/// under the target's name. A target that exists and is not a regular file (a device such
/// as /dev/null, a pipe, a socket) is written in place instead, and commit() closes it.
class AtomicFile {
public:
  explicit AtomicFile(const std::string &target);
  ~AtomicFile();
  AtomicFile(const AtomicFile &) = delete;
  AtomicFile &operator=(const AtomicFile &) = delete;
  void write(const char *data, size_t size);
  void commit();

private:
  std::string target_;
  TempFile tmp_;
  int fd_ = -1;
  uint64_t written_ = 0;  // bytes written so far
  bool in_place_ = false; // the target is not a regular file: written directly
};

/// Writes a file atomically from pieces, through a 1 MiB buffer: put() / reserve() fill
/// it, commit() flushes, fsyncs and renames the temporary file over the target. Destroyed
/// without commit(), it removes the temporary file.
class ChunkedFileWriter {
public:
  /// `bytes`: what the file will hold, if known (a small file gets a small buffer).
  explicit ChunkedFileWriter(const std::string &target, uint64_t bytes = UINT64_MAX);
  void put(const void *data, size_t size);
  /// Room for `size` (<= 4096) bytes at the end of the buffer, which the caller fills.
  char *reserve(size_t size) {
    if (used_ + size > capacity_)
      flush();
    char *p = buf_.get() + used_;
    used_ += size;
    return p;
  }
  void commit();

private:
  void flush();
  AtomicFile file_;
  std::unique_ptr<char[]> buf_; // (not zeroed: every byte is written before it is flushed)
  size_t capacity_ = 0, used_ = 0;
};

/// A file written atomically in chunks by the text writers (OBJ, OFF, ASCII PLY and STL,
/// PLY with attributes): they append a record at a time (a line, a facet, a run of binary
/// vertices) to text() and call done() after each, which hands the text to the file once
/// it holds kChunk bytes, so the whole text is never in memory. The temporary file is
/// created at the first hand-over (a header that turns out unwritable fails before any
/// file exists); commit() writes the rest and renames it over the target.
class TextFileWriter {
public:
  static constexpr size_t kChunk = size_t(1) << 20;
  explicit TextFileWriter(const std::string &target);
  std::string &text() { return text_; }
  void done() {
    if (text_.size() >= kChunk)
      flush();
  }
  void commit();

private:
  void flush();
  std::string target_;
  std::unique_ptr<AtomicFile> file_;
  std::string text_;
};

// ---- The vcglib mesh the importers fill ----

class IoVertex;
class IoEdge;
class IoFace;
struct IoTypes : vcg::UsedTypes<vcg::Use<IoVertex>::AsVertexType, vcg::Use<IoEdge>::AsEdgeType,
                                vcg::Use<IoFace>::AsFaceType> {};
// Per-vertex colour, normal, quality and texture coordinates hold the attributes a file
// keeps (PLY: read by our walk and stored here; OFF: by vcglib's importer), so that
// from_vcg drops them with their unreferenced vertices.
class IoVertex
    : public vcg::Vertex<IoTypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f, vcg::vertex::Color4b,
                         vcg::vertex::Qualityf, vcg::vertex::TexCoord2f, vcg::vertex::BitFlags> {};
// Edges only so that the PLY importer has somewhere to put an "edge" element: without an
// edge container it asserts. They are dropped.
class IoEdge : public vcg::Edge<IoTypes, vcg::edge::VertexRef, vcg::edge::BitFlags> {};
class IoFace : public vcg::Face<IoTypes, vcg::face::VertexRef, vcg::face::BitFlags> {};
class IoMesh
    : public vcg::tri::TriMesh<std::vector<IoVertex>, std::vector<IoFace>, std::vector<IoEdge>> {
public:
  IoMesh() = default;
  IoMesh(const IoMesh &) = delete; // the attribute handles below are owned, not copyable
  IoMesh &operator=(const IoMesh &) = delete;
  // vcglib's ~TriMesh leaves the user attributes (the PLY readers' per-vertex colour,
  // normals, scalars...) allocated: free them here.
  ~IoMesh() { ClearAttributes(); }
};

/// vcglib's message for an importer/exporter code, guarding against its off-by-one
/// tables (codes at the table size, empty entries).
template <class Io> std::string vcg_message(int code, int table_size) {
  const char *text = code >= 0 && code < table_size ? Io::ErrorMsg(code) : nullptr;
  if (text == nullptr || *text == '\0')
    return "error code " + std::to_string(code);
  return text;
}

/// The PLY importer copies a "flags" property into the bit flags, deleted bits included.
/// Those flags mean something else outside vcglib (whose exporter never writes deleted
/// elements), so they are ignored: every element read is kept.
void clear_flags(IoMesh &m);
/// Throws naming vertex i (STL: and its facet) if a coordinate is NaN or infinite.
void check_finite(float x, float y, float z, size_t i, const std::string &path, bool stl);
/// Throws naming the first vertex (in file order) with a NaN or infinite coordinate.
void check_finite(const IoMesh &m, const std::string &path, bool stl);
/// Throws unless vcglib built exactly the vertices and triangles the structure walk saw.
void check_counts(const IoMesh &m, size_t vertices, size_t triangles, const std::string &path,
                  const char *what);

/// Runs a vcglib call, turning its C++ exceptions (bad_alloc for absurd counts, ...) into
/// pomar::Error.
template <class F> auto guarded(const std::string &path, F &&call) -> decltype(call()) {
  try {
    return call();
  } catch (const Error &) {
    throw;
  } catch (const std::bad_alloc &) {
    fail(Error::Kind::MemoryLimit, path, "out of memory while reading");
  } catch (const std::exception &e) {
    fail(path, std::string("read failed: ") + e.what());
  }
}

// ---- Writing (io_common.cpp) ----

/// Appends "x y z" with full float precision.
void append_point(std::string &out, const float *p);
/// Writes the triangles as "<prefix>a b c\n" lines, indices offset by `base`.
void append_triangles(TextFileWriter &out, const Mesh &mesh, const char *prefix, uint64_t base);
/// Writes the positions as "<prefix>x y z\n" lines.
void append_vertices(TextFileWriter &out, const Mesh &mesh, const char *prefix);
/// Vertices no triangle uses.
size_t count_unreferenced(const Mesh &mesh);
/// Checks that a file written by a vcglib exporter has the expected size: the exporters
/// do not report failed writes (full disk), so a short file would otherwise go unnoticed.
void check_written_size(const std::string &file, uint64_t expected, const std::string &target);

// ---- One reader and writer per format ----

// ply_reader.cpp (load_ply), ply_writer.cpp (the writers)
Mesh load_ply(const std::string &path, LoadReport &report, const SizeCheck &check);
void write_ply_ascii(TextFileWriter &out, const Mesh &mesh);
/// Binary little-endian PLY, byte for byte what vcglib's exporter writes, from the flat
/// arrays in large chunks (save_ply_binary_vcg: through vcglib's exporter, the reference
/// the tests compare with and the path on big-endian hosts).
void save_ply_binary(const std::string &path, const Mesh &mesh);
void save_ply_binary_vcg(const std::string &path, const Mesh &mesh);
/// The header of the binary PLY files save_ply_binary writes (vcglib's, for float x, y, z
/// and triangles): `vertices` records of 12 bytes follow it, then `faces` of 13.
std::string binary_ply_header(uint64_t vertices, uint64_t faces);
/// A PLY file (ASCII or binary little-endian) with the mesh's attributes as vertex
/// properties (red green blue [alpha] uchar, nx ny nz, texture_u texture_v, one float per
/// scalar by its name), "comment TextureFile" lines and, as MeshLab writes them, the
/// per-corner texture coordinates as a face list "texcoord" (uchar 6, float u v per corner)
/// and the face materials as a face "texnumber" (int: the material's texture, -1 for none).
void write_ply_with_attributes(TextFileWriter &out, const Mesh &mesh, bool binary,
                               const std::string &path);
// off_io.cpp
Mesh load_off(const std::string &path, LoadReport &report, const SizeCheck &check);
/// OFF text; per-vertex normals and colour (8-bit integers, RGB or RGBA) when the mesh has
/// them ("[C][N]OFF": what vcglib's importer reads back exactly).
void write_off(TextFileWriter &out, const Mesh &mesh);
// stl_io.cpp
Mesh load_stl(const std::string &path, LoadReport &report, const SizeCheck &check);
/// ASCII STL; the facet normal is the normalized cross product (0 for a degenerate facet).
void write_stl_ascii(TextFileWriter &out, const Mesh &mesh);
/// Binary STL, byte for byte what vcglib's exporter writes, from the flat arrays in large
/// chunks (save_stl_binary_vcg: through vcglib's exporter via a temporary file, the path on
/// big-endian hosts).
void save_stl_binary(const std::string &path, const Mesh &mesh);
void save_stl_binary_vcg(const std::string &path, const Mesh &mesh);
// obj_io.cpp
Mesh load_obj(const std::string &path, LoadReport &report, const SizeCheck &check);
/// The OBJ text; `mtllib` (if not empty) is the material library it names. Per-corner
/// texture coordinates are written as "vt" lines (each distinct pair once) and "f v/vt"
/// corners; faces go in runs of one material, each run after a "usemtl" line (a run of the
/// material with the empty name: after a bare "usemtl", or first without one). A mesh
/// without materials uses the library's material "texture_0".
void write_obj(TextFileWriter &out, const Mesh &mesh, const std::string &mtllib);
/// The material library: per material (except the one with the empty name), "newmtl",
/// its properties as they are and "map_Kd" with its texture file (unless the properties
/// hold a map_Kd line). A mesh without materials gets one material "texture_<i>" per
/// texture file.
std::string mtl_text(const Mesh &mesh);

} // namespace pomar::io
