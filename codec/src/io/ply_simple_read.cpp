// The common PLY shape (float x, y, z; triangles as uchar-counted int lists) read straight
// into the flat arrays, binary little-endian in large reads or ASCII in 1 MiB chunks, with
// no vcglib mesh in between.
#include "io/ply_internal.h"
#include "memory/prefault.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace pomar::io {
namespace {

/// The common shape read straight into the flat arrays: a vertex element of exactly float
/// x, y, z, then a face element of exactly one uchar-counted int or uint "vertex_indices"
/// list.
bool simple_shape(const PlyHeader &h) {
  if (h.elements.size() != 2)
    return false;
  const PlyElement &ve = h.elements[0], &fe = h.elements[1];
  if (ve.name != "vertex" || ve.props.size() != 3 || fe.name != "face" || fe.props.size() != 1)
    return false;
  for (int k = 0; k < 3; ++k)
    if (ve.props[size_t(k)].is_list || ve.props[size_t(k)].type != PlyType::F32 ||
        ve.props[size_t(k)].name != std::string(1, char('x' + k)))
      return false;
  const PlyProperty &list = fe.props[0];
  return list.name == "vertex_indices" && is_list_of(&list, list.type, PlyType::U8) &&
         (list.type == PlyType::I32 || list.type == PlyType::U32);
}

/// Binary little-endian data of the simple shape (all triangles, finite coordinates):
/// positions in one read, faces in chunks; `used` marks the vertices the faces use.
bool read_simple_binary(FileReader &in, uint64_t nv, uint64_t nf, Mesh &out,
                        std::vector<uint8_t> &used) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  if (in.remaining() / 13 < nf || in.remaining() - 13 * nf < 12 * nv)
    return false;
  resize_prefaulted(out.positions, 3 * nv); // (written whole: memory/prefault.h)
  if (!in.read(out.positions.data(), 12 * nv))
    return false;
  for (uint64_t i = 0; i < 3 * nv; ++i)
    if (!std::isfinite(out.positions[i]))
      return false;
  resize_prefaulted(out.triangles, 3 * nf);
  constexpr uint64_t kChunk = 65536;
  std::vector<unsigned char> buf(13 * kChunk);
  for (uint64_t f0 = 0; f0 < nf; f0 += kChunk) {
    const uint64_t n = std::min(kChunk, nf - f0);
    if (!in.read(buf.data(), 13 * n))
      return false;
    for (uint64_t f = 0; f < n; ++f) {
      const unsigned char *p = &buf[13 * f];
      if (p[0] != 3)
        return false;
      uint32_t *t = &out.triangles[3 * (f0 + f)];
      std::memcpy(t, p + 1, 12);
      for (int k = 0; k < 3; ++k) { // (int indices: negative ones are >= nv as uint32)
        if (t[k] >= nv)
          return false;
        used[t[k]] = 1;
      }
    }
  }
  return true;
#else
  (void)in, (void)nv, (void)nf, (void)out, (void)used;
  return false;
#endif
}

/// The whitespace-separated tokens of the rest of a file (whitespace as fscanf has it),
/// read in chunks of 1 MiB.
class AsciiTokens {
public:
  explicit AsciiTokens(FileReader &in) : in_(in), buf_(kChunk + kMaxToken) {}

  /// The next token in [b, e); false at the end of the file or on a token too long for a
  /// number.
  bool next(const char *&b, const char *&e) {
    for (;;) { // skip whitespace
      while (pos_ < end_ && space(buf_[pos_]))
        ++pos_;
      if (pos_ < end_)
        break;
      if (!refill())
        return false;
    }
    size_t i = pos_;
    for (;;) {
      while (i < end_ && !space(buf_[i]))
        ++i;
      if (i < end_ || in_.remaining() == 0)
        break;
      if (i - pos_ >= kMaxToken) // a token this long is not a number of ours
        return false;
      const size_t scanned = i - pos_;
      if (!refill())
        return false;
      i = pos_ + scanned;
    }
    if (i - pos_ >= kMaxToken)
      return false;
    b = &buf_[pos_];
    e = &buf_[i];
    pos_ = i;
    return true;
  }

private:
  static constexpr size_t kChunk = size_t(1) << 20, kMaxToken = 64;
  static bool space(char c) {
    return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f';
  }
  /// Keeps the unread bytes (at most a token), appends the next chunk; false if none.
  bool refill() {
    const size_t n = std::min<uint64_t>(kChunk, in_.remaining());
    if (n == 0 || end_ - pos_ > kMaxToken)
      return false;
    std::memmove(buf_.data(), buf_.data() + pos_, end_ - pos_);
    end_ -= pos_;
    pos_ = 0;
    if (!in_.read(buf_.data() + end_, n))
      return false;
    end_ += n;
    return true;
  }

  FileReader &in_;
  std::vector<char> buf_;
  size_t pos_ = 0, end_ = 0;
};

/// ASCII data of the simple shape, as vcglib reads it: plain decimal coordinates (finite),
/// faces "3 a b c" with indices in range, nothing after the last face.
bool read_simple_ascii(FileReader &in, uint64_t nv, uint64_t nf, Mesh &out,
                       std::vector<uint8_t> &used) {
  if (nv > in.remaining() / 6 || nf > (in.remaining() + 1 - 6 * nv) / 8)
    return false; // an ASCII vertex takes 6 bytes or more, a face 8
  AsciiTokens tokens(in);
  const char *b = nullptr, *e = nullptr;
  resize_prefaulted(out.positions, 3 * nv); // (written whole: memory/prefault.h)
  for (float &x : out.positions) {
    if (!tokens.next(b, e) || !plain_decimal(b, e))
      return false;
    const auto r = std::from_chars(b, e, x);
    if (r.ec != std::errc() || r.ptr != e || !std::isfinite(x))
      return false;
  }
  resize_prefaulted(out.triangles, 3 * nf);
  for (uint64_t f = 0; f < nf; ++f) {
    if (!tokens.next(b, e) || e - b != 1 || *b != '3')
      return false;
    for (int k = 0; k < 3; ++k) {
      uint64_t v = 0;
      if (!tokens.next(b, e) || !parse_digits(b, e, nv - 1, v))
        return false;
      out.triangles[3 * f + k] = static_cast<uint32_t>(v);
      used[v] = 1;
    }
  }
  return !tokens.next(b, e);
}

} // namespace

bool read_simple_ply(FileReader &in, const PlyHeader &h, Mesh &out, size_t &unreferenced) {
  if (!simple_shape(h))
    return false;
  const uint64_t nv = h.elements[0].count, nf = h.elements[1].count;
  if (nv == 0 || nf == 0 || nv >= UINT32_MAX || nf > UINT32_MAX / 3)
    return false;
  std::vector<uint8_t> used = filled_vector<uint8_t>(nv);
  Mesh mesh;
  if (h.encoding == PlyHeader::BinaryLittle) {
    if (!read_simple_binary(in, nv, nf, mesh, used))
      return false;
  } else if (h.encoding == PlyHeader::Ascii) {
    if (!read_simple_ascii(in, nv, nf, mesh, used))
      return false;
  } else {
    return false;
  }
  // As from_vcg(..., keep_unreferenced): vertices no face uses are counted and kept (the
  // codec stores them).
  unreferenced = static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
  out = std::move(mesh);
  return true;
}

} // namespace pomar::io
