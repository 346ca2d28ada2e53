// Shared helpers of the mesh readers and writers (declared in io_common.h).
#include "io/io_common.h"
#include "memory/prefault.h"

#include <wrap/io_trimesh/io_mask.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <system_error>

namespace pomar::io {

[[noreturn]] void fail(Error::Kind kind, const std::string &path, const std::string &what) {
  throw Error(kind, path + ": " + what).with_path(path);
}

[[noreturn]] void fail(const std::string &path, const std::string &what) {
  fail(Error::Kind::InvalidMesh, path, what);
}

[[noreturn]] void fail_io(const std::string &path, const std::string &what) {
  fail(Error::Kind::Io, path, what);
}

void run_size_check(const SizeCheck &check, const std::string &path, uint64_t vertices,
                    uint64_t faces) {
  if (!check)
    return;
  try {
    check(vertices, faces);
  } catch (const Error &e) {
    fail(e.kind(), path, e.what());
  }
}

std::string errno_text(int e) { return std::generic_category().message(e); }

std::string errno_suffix() { return errno ? " (" + errno_text(errno) + ")" : std::string(); }

std::string num(uint64_t v) { return std::to_string(v); }

void append_float(std::string &out, float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 9);
  out.append(buf, r.ptr);
}

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

bool parse_count(const std::string &token, uint64_t max, uint64_t &value) {
  if (token.empty() || token.size() > 19)
    return false;
  const auto r = std::from_chars(token.data(), token.data() + token.size(), value);
  return r.ec == std::errc() && r.ptr == token.data() + token.size() && value <= max;
}

bool parse_int(const std::string &token, int64_t &value) {
  const char *begin = token.data(), *end = begin + token.size();
  if (begin != end && *begin == '+')
    ++begin; // from_chars does not take a leading '+'
  const auto r = std::from_chars(begin, end, value);
  return begin != end && r.ec == std::errc() && r.ptr == end;
}

bool parse_float(const std::string &token, float &value) {
  // Plain decimal text, the common case: from_chars rounds it as strtof does, at a fraction
  // of the cost; what it does not take (out of range included) goes to strtof.
  const char *b = token.data(), *e = b + token.size();
  if (plain_decimal(b, e)) {
    float x;
    const auto r = std::from_chars(b, e, x);
    if (r.ec == std::errc() && r.ptr == e) {
      value = x;
      return true;
    }
  }
  if (token.empty() || token.find_first_of("xX") != std::string::npos)
    return false;
  char *end = nullptr;
  errno = 0;
  value = std::strtof(token.c_str(), &end);
  return end == token.c_str() + token.size();
}

bool plain_decimal(const char *b, const char *e) {
  if (b != e && *b == '-')
    ++b;
  bool digits = false;
  while (b != e && *b >= '0' && *b <= '9')
    ++b, digits = true;
  if (b != e && *b == '.')
    for (++b; b != e && *b >= '0' && *b <= '9'; ++b)
      digits = true;
  if (!digits)
    return false;
  if (b != e && (*b == 'e' || *b == 'E')) {
    ++b;
    if (b != e && (*b == '-' || *b == '+'))
      ++b;
    if (b == e || *b < '0' || *b > '9')
      return false;
    while (b != e && *b >= '0' && *b <= '9')
      ++b;
  }
  return b == e;
}

bool parse_digits(const char *b, const char *e, uint64_t max, uint64_t &value) {
  if (b == e || *b < '0' || *b > '9') // (from_chars would take a '-')
    return false;
  const auto r = std::from_chars(b, e, value);
  return r.ec == std::errc() && r.ptr == e && value <= max;
}

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

uint64_t check_regular_file(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    fail_io(path, "cannot open: " + errno_text(errno));
  FdGuard guard(fd);
  struct stat st;
  if (::fstat(fd, &st) != 0)
    fail_io(path, "cannot stat: " + errno_text(errno));
  if (S_ISDIR(st.st_mode))
    fail_io(path, "is a directory");
  if (!S_ISREG(st.st_mode))
    fail_io(path, "not a regular file");
  return static_cast<uint64_t>(st.st_size);
}

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

AtomicFile::AtomicFile(const std::string &target) : target_(target), tmp_(target) {
  struct stat st;
  if (::stat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode))
      fail_io(target_, "is a directory");
    // A device, a pipe or a socket (/dev/null, /dev/stdout, a FIFO) is written in place:
    // renaming a file over it would replace the device with a regular file.
    in_place_ = true;
    fd_ = ::open(target_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0)
      fail_io(target_, "cannot open for writing: " + errno_text(errno));
    return;
  }
  fd_ = ::open(tmp_.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd_ < 0)
    fail_io(target_, "cannot create temporary file '" + tmp_.path() + "': " + errno_text(errno));
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0)
    ::close(fd_);
}

void AtomicFile::write(const char *data, size_t size) {
  if (!write_all(fd_, data, size))
    fail_io(target_, "cannot write: " + errno_text(errno));
#if defined(__linux__) && defined(SYNC_FILE_RANGE_WRITE)
  if (!in_place_)
    // Start writing these bytes to the disk now, without waiting (commit()'s fsync then
  // waits for less); a file system that cannot says so, and nothing changes.
    ::sync_file_range(fd_, off_t(written_), off_t(size), SYNC_FILE_RANGE_WRITE);
#endif
  written_ += size;
}

void AtomicFile::commit() {
  if (in_place_) { // (a device or a pipe: nothing to sync or rename)
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0)
      fail_io(target_, "cannot write (close): " + errno_text(errno));
    return;
  }
  if (::fsync(fd_) != 0)
    fail_io(target_, "fsync failed: " + errno_text(errno));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0)
    fail_io(target_, "cannot write (close): " + errno_text(errno));
  tmp_.commit(false);
}

ChunkedFileWriter::ChunkedFileWriter(const std::string &target, uint64_t bytes) : file_(target) {
  constexpr uint64_t kChunk = uint64_t(1) << 20;
  capacity_ = static_cast<size_t>(std::clamp<uint64_t>(bytes, 8192, kChunk));
  buf_.reset(new char[capacity_]);
  prefault(buf_.get(), capacity_); // (written whole: mapped first, in one call)
}

void ChunkedFileWriter::flush() {
  file_.write(buf_.get(), used_);
  used_ = 0;
}

void ChunkedFileWriter::put(const void *data, size_t size) {
  const char *p = static_cast<const char *>(data);
  while (size > 0) {
    if (used_ == capacity_)
      flush();
    const size_t n = std::min(size, capacity_ - used_);
    std::memcpy(buf_.get() + used_, p, n);
    used_ += n, p += n, size -= n;
  }
}

void ChunkedFileWriter::commit() {
  flush();
  file_.commit();
}

TextFileWriter::TextFileWriter(const std::string &target) : target_(target) {
  text_.reserve(kChunk + 4096);
  prefault(text_.data(), text_.capacity()); // (written whole: mapped first, in one call)
}

void TextFileWriter::flush() {
  if (!file_)
    file_ = std::make_unique<AtomicFile>(target_);
  file_->write(text_.data(), text_.size());
  text_.clear();
}

void TextFileWriter::commit() {
  flush();
  file_->commit();
}

void clear_flags(IoMesh &m) {
  for (auto &v : m.vert)
    v.Flags() = 0;
  for (auto &f : m.face)
    f.Flags() = 0;
}

void check_finite(float x, float y, float z, size_t i, const std::string &path, bool stl) {
  if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z))
    return;
  const std::string where = stl ? " (facet " + num(i / 3) + ")" : "";
  fail(path, "vertex " + num(i) + where + " has a non-finite coordinate " + point_text(x, y, z));
}

void check_finite(const IoMesh &m, const std::string &path, bool stl) {
  for (size_t i = 0; i < m.vert.size(); ++i)
    check_finite(m.vert[i].cP()[0], m.vert[i].cP()[1], m.vert[i].cP()[2], i, path, stl);
}

void check_counts(const IoMesh &m, size_t vertices, size_t triangles, const std::string &path,
                  const char *what) {
  if (m.vert.size() == vertices && m.face.size() == triangles)
    return;
  fail(path, std::string(what) + " read " + num(m.vert.size()) + " vertices and " +
                 num(m.face.size()) + " triangles, but the file describes " + num(vertices) +
                 " vertices and " + num(triangles) + " triangles (unsupported property type?)");
}

void append_point(std::string &out, const float *p) {
  append_float(out, p[0]);
  out += ' ';
  append_float(out, p[1]);
  out += ' ';
  append_float(out, p[2]);
}

void append_triangles(TextFileWriter &out, const Mesh &mesh, const char *prefix, uint64_t base) {
  std::string &s = out.text();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    s += prefix;
    for (int k = 0; k < 3; ++k) {
      if (k)
        s += ' ';
      append_uint(s, mesh.triangles[3 * t + k] + base);
    }
    s += '\n';
    out.done();
  }
}

size_t count_unreferenced(const Mesh &mesh) {
  std::vector<uint8_t> used(mesh.vertex_count(), 0);
  for (uint32_t t : mesh.triangles)
    used[t] = 1;
  return static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
}

void append_vertices(TextFileWriter &out, const Mesh &mesh, const char *prefix) {
  std::string &s = out.text();
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    s += prefix;
    append_point(s, &mesh.positions[3 * v]);
    s += '\n';
    out.done();
  }
}

void check_written_size(const std::string &file, uint64_t expected, const std::string &target) {
  struct stat st;
  if (::stat(file.c_str(), &st) != 0)
    fail_io(target, "cannot stat temporary file: " + errno_text(errno));
  if (static_cast<uint64_t>(st.st_size) != expected)
    fail_io(target, "short write (" + num(uint64_t(st.st_size)) + " of " + num(expected) +
                        " bytes; disk full?)");
}

} // namespace pomar::io
