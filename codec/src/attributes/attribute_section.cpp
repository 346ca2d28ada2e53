// Per-vertex attributes in the bitstream: the ATTR section (descriptors, texture files, the
// base mesh's codes) and the pieces the level coding shares (byte layout: docs/format.md).
#include "attributes/attribute_section.h"

#include <algorithm>
#include <string>

#include "attributes/wedge_prediction.h"
#include "format/bit_io.h"
#include "lossless/seam_cut.h"
#include "refine/level_traversal.h"

namespace pomar {
namespace {

[[noreturn]] void damaged(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: ATTR section: " + what);
}

/// Range-code `count` vertices of codes, each predicted by the previous one (the first by
/// zeros): the base mesh's codes.
template <class Coder> void code_base(Coder &&code_one, uint32_t count, uint32_t n) {
  for (uint32_t v = 0; v < count; ++v)
    for (uint32_t k = 0; k < n; ++k)
      code_one(v, k);
}

/// The flags byte of a descriptor (ATTR section versions 2 to 4).
constexpr uint8_t kZeroNormalsFlag = 1; // a quantized normal attribute with zero-length normals
// The wedge texcoord predicted from the positions (version 3): in the levels, in the base mesh;
// (version 4) in the levels its mask names.
constexpr uint8_t kPositionsFlag = 2, kBasePositionsFlag = 4, kLevelPositionsFlag = 8;
bool is_wedge_grid(const StoredAttribute &s) {
  return s.kind == AttributeKind::TexCoord && s.bits && s.name == kWedgeTexcoord;
}
bool positions_predict(const StoredAttribute &s) { return is_wedge_grid(s) && s.from_positions; }
bool base_positions_predict(const StoredAttribute &s) {
  return is_wedge_grid(s) && s.base_from_positions;
}
bool level_positions_predict(const StoredAttribute &s) {
  return is_wedge_grid(s) && !s.level_positions.empty();
}
uint8_t descriptor_flags(const StoredAttribute &s) {
  return uint8_t(
      (s.kind == AttributeKind::Normal && s.bits && s.zero_normals ? kZeroNormalsFlag : 0) |
      (positions_predict(s) ? kPositionsFlag : 0) |
      (base_positions_predict(s) ? kBasePositionsFlag : 0) |
      (level_positions_predict(s) ? kLevelPositionsFlag : 0));
}

/// kind, name, components, bits and bound of a stored attribute into a VertexAttribute or
/// an AttributeInfo.
template <class Out> Out described(const StoredAttribute &s) {
  Out a;
  a.kind = s.kind;
  a.name = s.name;
  a.components = s.components;
  a.bits = s.bits;
  a.bound = s.bound();
  return a;
}

/// Whether the table's wedge texture coordinate is predicted from the positions in the
/// levels (or, `base`, in the base mesh).
bool wedge_positions(const AttributeTable &t, bool base = false) {
  for (const StoredAttribute &s : t.stored)
    if (base ? base_positions_predict(s) : positions_predict(s))
      return true;
  return false;
}

/// The wedge texture coordinate of base vertex v (codes k0, k0 + 1 of n a vertex in
/// `codes`) predicted by the mean of its neighbours numbered below v in the base mesh `ct`
/// (one chart: the seam cut separates the charts), rounded half away from zero, or by
/// vertex v - 1's if it has none (zeros for vertex 0). With positions `q` (a file whose
/// wedge texture coordinate is predicted from the positions), from the faces of v's
/// neighbours a < v whose vertices are all numbered below v, if any, in the order of v's
/// ring and of each a's ring (attributes/wedge_prediction.h); `lo` and `hi` are the codes'
/// ranges.
void predict_wedge_base(const CornerTable &ct, const std::vector<int64_t> &codes, uint32_t n,
                        int k0, uint32_t v, Ring &ring, int64_t pred[2],
                        const std::vector<int32_t> *q = nullptr, const int64_t *lo = nullptr,
                        const int64_t *hi = nullptr) {
  int64_t su = 0, sv = 0, count = 0;
  if (ct.VC[v] != kNone) {
    get_ring(ct, v, ring);
    if (q) {
      const auto uv = [&](uint32_t u) { return &codes[size_t(u) * n + size_t(k0)]; };
      const auto at = [&](uint32_t u) { return &(*q)[3 * size_t(u)]; };
      WedgeFromPositions w(at(v));
      Ring fan;
      for (uint32_t a : ring.neighbour) {
        if (a >= v)
          continue;
        get_ring(ct, a, fan);
        for (uint32_t i = 0; i < fan.faces(); ++i) {
          const uint32_t b = fan.neighbour[i], c = fan.neighbour[(i + 1) % fan.size()];
          if (b < v && c < v)
            w.add(at(a), at(b), at(c), uv(a), uv(b), uv(c));
        }
      }
      if (w.get(lo, hi, pred))
        return;
    }
    for (uint32_t u : ring.neighbour)
      if (u < v) {
        su += codes[size_t(u) * n + size_t(k0)];
        sv += codes[size_t(u) * n + size_t(k0) + 1];
        ++count;
      }
  }
  if (count == 0) {
    pred[0] = v ? codes[size_t(v - 1) * n + size_t(k0)] : 0;
    pred[1] = v ? codes[size_t(v - 1) * n + size_t(k0) + 1] : 0;
    return;
  }
  const auto mean = [count](int64_t x) { return (x >= 0 ? x + count / 2 : x - count / 2) / count; };
  pred[0] = mean(su);
  pred[1] = mean(sv);
}

/// The first code of the wedge texture coordinate among the table's attributes, or -1.
int wedge_code(const AttributeTable &t) {
  int k = 0;
  for (const StoredAttribute &s : t.stored) {
    if (s.kind == AttributeKind::TexCoord && s.name == kWedgeTexcoord)
      return k;
    k += int(s.codes());
  }
  return -1;
}

/// The base mesh's codes stream of a table (the wedge texture coordinate's residuals from
/// `wedge_residuals` if it has them).
std::vector<uint8_t> base_codes_stream(const AttributeTable &t, uint32_t count) {
  const uint32_t n = t.codes;
  std::vector<uint8_t> stream;
  RangeEncoder rc(&stream);
  std::vector<AttributeCodeModels> m = attribute_models(t);
  std::vector<int64_t> r(n);
  const int wedge = t.wedge_residuals.empty() ? -1 : t.wedge_uv;
  code_base(
      [&](uint32_t v, uint32_t k) {
        const int64_t pred = v ? t.base[size_t(v - 1) * n + k] : 0;
        r[k] = wedge >= 0 && (int(k) == wedge || int(k) == wedge + 1)
                   ? t.wedge_residuals[2 * size_t(v) + (k - uint32_t(wedge))]
                   : t.base[size_t(v) * n + k] - pred;
        put_signed(rc, m[k].classes[attribute_context(m[k], r.data(), k)], m[k].top, r[k]);
      },
      count, n);
  rc.finish();
  return stream;
}

} // namespace

void plan_wedge_residuals(AttributeTable &t, const LevelMesh &base) {
  t.wedge_residuals.clear();
  if (t.wedge_uv < 0 || t.codes == 0)
    return;
  const uint32_t n = t.codes, count = static_cast<uint32_t>(t.base.size() / n);
  const size_t k0 = size_t(t.wedge_uv);
  const auto residuals = [&](bool positions) {
    std::vector<int64_t> out(2 * size_t(count));
    Ring ring;
    for (uint32_t v = 0; v < count; ++v) {
      int64_t pred[2];
      predict_wedge_base(base.ct, t.base, n, t.wedge_uv, v, ring, pred,
                         positions ? &base.q : nullptr, &base.attr_lo[k0], &base.attr_hi[k0]);
      for (int j = 0; j < 2; ++j)
        out[2 * size_t(v) + j] = t.base[size_t(v) * n + k0 + j] - pred[j];
    }
    return out;
  };
  t.wedge_residuals = residuals(false);
  for (StoredAttribute &s : t.stored)
    if (is_wedge_grid(s) && s.base_from_positions) {
      // From the positions or by the mean, whichever codes smaller.
      const size_t mean_bytes = base_codes_stream(t, count).size();
      std::vector<int64_t> other = residuals(true);
      t.wedge_residuals.swap(other);
      if (base_codes_stream(t, count).size() >= mean_bytes) {
        t.wedge_residuals.swap(other);
        s.base_from_positions = false;
      }
    }
}

bool has_wedge_grid(const AttributeTable &table) {
  for (const StoredAttribute &s : table.stored)
    if (is_wedge_grid(s))
      return true;
  return false;
}

bool base_wedge_from_positions(const AttributeTable &table) { return wedge_positions(table, true); }

void set_wedge_levels(AttributeTable &table, const std::vector<uint8_t> &positions) {
  // Every level from the positions: the positions flag (version 3); none: no flag; a mix:
  // the level mask (version 4).
  const auto first = positions.begin() + std::min<size_t>(1, positions.size());
  const size_t ones = size_t(std::count(first, positions.end(), uint8_t(1)));
  const size_t levels = size_t(positions.end() - first);
  for (StoredAttribute &s : table.stored)
    if (is_wedge_grid(s)) {
      s.from_positions = ones > 0 && ones == levels;
      s.level_positions.clear();
      if (ones > 0 && ones < levels)
        s.level_positions.assign(first, positions.end());
    }
}

AttributeTable plan_attributes(const Mesh &mesh, const AttributeOptions &options) {
  AttributeTable t;
  for (const VertexAttribute &a : mesh.attributes)
    if (keeps_attribute(a.name, a.kind, options.keep)) {
      if (a.name == kWedgeMaterial) { // integers: a grid of at most one unit a step
        AttributeOptions exact_integers = options;
        const float hi =
            a.values.empty() ? 0.0f : *std::max_element(a.values.begin(), a.values.end());
        exact_integers.scalar_bits = 1;
        while (exact_integers.scalar_bits < 24 && double(1u << exact_integers.scalar_bits) <= hi)
          ++exact_integers.scalar_bits;
        t.stored.push_back(describe(a, exact_integers));
      } else {
        t.stored.push_back(describe(a, options));
        // (plan_wedge_residuals keeps the base mesh's prediction from the positions only
        // if it codes smaller; the levels' are set after them, set_wedge_levels)
        t.stored.back().base_from_positions = a.name == kWedgeTexcoord;
      }
      t.codes += t.stored.back().codes();
    }
  if (t.stored.size() > 255)
    throw Error(Error::Kind::InvalidMesh, "at most 255 attributes can be stored (the mesh has " +
                                              std::to_string(t.stored.size()) + ")");
  if (t.codes > kMaxAttributeCodes)
    throw Error(Error::Kind::InvalidMesh,
                "the attributes need " + std::to_string(t.codes) + " values per vertex; at most " +
                    std::to_string(kMaxAttributeCodes) +
                    " are supported (colour 3-4, quantized normal 2, texcoord 2, scalar 1): "
                    "drop some (--drop)");
  if (options.keep.texcoords)
    t.texture_files = mesh.texture_files;
  t.estimated_bytes.assign(t.stored.size(), 0);
  t.wedge_uv = wedge_code(t);
  return t;
}

std::vector<int64_t> attribute_codes(const Mesh &mesh, const AttributeTable &table,
                                     const AttributeOptions &options,
                                     const std::vector<uint32_t> &to_input) {
  std::vector<const VertexAttribute *> kept;
  for (const VertexAttribute &a : mesh.attributes)
    if (keeps_attribute(a.name, a.kind, options.keep))
      kept.push_back(&a);
  std::vector<int64_t> codes(to_input.size() * table.codes);
  for (size_t v = 0; v < to_input.size(); ++v) {
    int64_t *c = &codes[v * table.codes];
    for (size_t i = 0; i < kept.size(); ++i) {
      to_codes(table.stored[i], *kept[i], to_input[v], c);
      c += table.stored[i].codes();
    }
  }
  return codes;
}

std::vector<AttributeCodeModels> attribute_models(const AttributeTable &table) {
  std::vector<AttributeCodeModels> models;
  for (const StoredAttribute &s : table.stored)
    for (uint32_t k = 0; k < s.codes(); ++k) {
      models.emplace_back();
      models.back().first = k == 0;
    }
  return models;
}

bool keeps_any(const AttributeTable &table, const AttributeMask &mask) {
  for (const StoredAttribute &s : table.stored)
    if (keeps_attribute(s.name, s.kind, mask))
      return true;
  return false;
}

void init_attributes(const AttributeTable &table, LevelMesh &lm, const AttributeMask &mask) {
  if (!keeps_any(table, mask)) { // read past the codes: no prediction, no storage
    lm.attr_codes = 0;
    lm.attr_skipped = table.codes;
    return;
  }
  lm.attr_skipped = 0;
  lm.attr_codes = table.codes;
  lm.attr = table.base;
  lm.attr_lo.clear();
  lm.attr_hi.clear();
  lm.normal_code = -1;
  lm.wedge_uv_code = table.wedge_uv;
  lm.wedge_uv_positions.clear();
  if (wedge_positions(table)) // (version 3: every level)
    lm.wedge_uv_positions.assign(1, 1);
  for (const StoredAttribute &s : table.stored)
    if (level_positions_predict(s)) { // level l at index l, then the mean past the last
      lm.wedge_uv_positions.assign(1, 0);
      lm.wedge_uv_positions.insert(lm.wedge_uv_positions.end(), s.level_positions.begin(),
                                   s.level_positions.end());
      lm.wedge_uv_positions.push_back(0);
    }
  lm.normal_zero = false;
  for (const StoredAttribute &s : table.stored) {
    if (s.kind == AttributeKind::Normal && s.bits && lm.normal_code < 0) {
      lm.normal_code = static_cast<int>(lm.attr_lo.size());
      lm.normal_bits = s.bits;
      lm.normal_zero = s.zero_normals;
    }
    for (uint32_t k = 0; k < s.codes(); ++k) {
      int64_t lo, hi;
      code_range(s, k, lo, hi);
      lm.attr_lo.push_back(lo);
      lm.attr_hi.push_back(hi);
    }
  }
  if (table.wedge_pending) { // the wedge residuals of a file, resolved in vertex order
    const uint32_t n = table.codes, count = static_cast<uint32_t>(table.base.size() / n);
    const size_t k0 = size_t(table.wedge_uv);
    const bool base_positions = wedge_positions(table, true);
    Ring ring;
    for (uint32_t v = 0; v < count; ++v) {
      int64_t pred[2];
      predict_wedge_base(lm.ct, lm.attr, n, table.wedge_uv, v, ring, pred,
                         base_positions ? &lm.q : nullptr, &lm.attr_lo[k0], &lm.attr_hi[k0]);
      for (size_t j = 0; j < 2; ++j) {
        int64_t &c = lm.attr[size_t(v) * n + k0 + j];
        c += pred[j];
        if (c < lm.attr_lo[k0 + j] || c > lm.attr_hi[k0 + j])
          damaged("a base mesh attribute lies outside its range");
      }
    }
  }
}

std::vector<uint8_t> write_attributes(const AttributeTable &t, uint32_t base_vertices) {
  std::vector<uint8_t> out;
  ByteWriter w(out);
  // Version 1 unless a descriptor needs its flags byte (version 2): files whose attributes
  // use no flag stay readable by readers of version 1.
  // Version 3 only when the wedge texture coordinate is predicted from the positions,
  // version 4 only when it says so level by level.
  bool flags = false, positions = false, levels = false;
  for (const StoredAttribute &s : t.stored) {
    flags |= descriptor_flags(s) != 0;
    positions |= positions_predict(s) || base_positions_predict(s);
    levels |= level_positions_predict(s);
  }
  w.u8(levels      ? kAttributeSectionLevelsVersion
       : positions ? kAttributeSectionPositionsVersion
       : flags     ? kAttributeSectionFlagsVersion
                   : kAttributeSectionVersion);
  w.u8(static_cast<uint8_t>(t.stored.size()));
  for (size_t i = 0; i < t.stored.size(); ++i) {
    const StoredAttribute &s = t.stored[i];
    w.u8(static_cast<uint8_t>(s.kind));
    w.u8(static_cast<uint8_t>(s.components));
    w.u8(static_cast<uint8_t>(s.bits));
    if (flags)
      w.u8(descriptor_flags(s));
    w.u8(static_cast<uint8_t>(s.name.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(s.name.data()), s.name.size());
    for (size_t k = 0; k < s.lo.size(); ++k) {
      w.f32(s.lo[k]);
      w.f32(s.hi[k]);
    }
    if (level_positions_predict(s)) { // u16 level count, then a bit per level
      if (s.level_positions.size() > 0xFFFF)
        throw Error(Error::Kind::Internal, "internal encoder error: more than 65535 levels");
      w.u16(static_cast<uint16_t>(s.level_positions.size()));
      for (size_t l = 0; l < s.level_positions.size(); l += 8) {
        uint8_t byte = 0;
        for (size_t b = 0; b < 8 && l + b < s.level_positions.size(); ++b)
          byte = uint8_t(byte | (s.level_positions[l + b] ? 1u << b : 0u));
        w.u8(byte);
      }
    }
    w.u32(static_cast<uint32_t>(t.estimated_bytes[i]));
    w.u32(static_cast<uint32_t>(t.estimated_bytes[i] >> 32));
  }
  if (t.texture_files.size() > 0xFFFF)
    throw Error(Error::Kind::InvalidMesh,
                "too many texture files (" + std::to_string(t.texture_files.size()) + ")");
  w.u16(static_cast<uint16_t>(t.texture_files.size()));
  for (const std::string &f : t.texture_files) {
    if (f.size() > 0xFFFF)
      throw Error(Error::Kind::InvalidMesh,
                  "texture file name too long: " + f.substr(0, 64) + "...");
    w.u16(static_cast<uint16_t>(f.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(f.data()), f.size());
  }
  // The base mesh's vertex count, also when no attribute has codes (texture file names only):
  // the reader checks it against the header.
  const uint32_t n = t.codes, count = base_vertices;
  if (size_t(count) * n != t.base.size())
    throw Error(
        Error::Kind::Internal,
        "internal encoder error: the base mesh's attribute codes do not match its vertices");
  w.u32(count);
  const std::vector<uint8_t> stream = base_codes_stream(t, count);
  w.u32(static_cast<uint32_t>(stream.size()));
  w.bytes(stream.data(), stream.size());
  return out;
}

AttributeTable read_attributes(const uint8_t *data, size_t size, uint32_t base_vertices,
                               bool keep_base) {
  ByteReader r(data, size, "damaged .pomar file: ATTR section");
  AttributeTable t;
  const uint8_t version = r.u8();
  if (version < kAttributeSectionVersion || version > kAttributeSectionLevelsVersion)
    throw Error(Error::Kind::Unsupported, "ATTR section version " + std::to_string(version) +
                                              " is not supported (this pomar reads versions 1 "
                                              "to 4)");
  const uint32_t count = r.u8();
  auto read_string = [&](size_t len) {
    std::string s;
    for (size_t i = 0; i < len; ++i)
      s.push_back(static_cast<char>(r.u8()));
    return s;
  };
  for (uint32_t i = 0; i < count; ++i) {
    StoredAttribute s;
    const uint8_t kind = r.u8();
    if (kind < 1 || kind > 4)
      damaged("attribute " + std::to_string(i) + " has unknown kind " + std::to_string(kind));
    s.kind = static_cast<AttributeKind>(kind);
    s.components = r.u8();
    s.bits = r.u8();
    const uint8_t flags = version != kAttributeSectionVersion ? r.u8() : 0;
    s.zero_normals = flags & kZeroNormalsFlag;
    const bool positions_flags = version >= kAttributeSectionPositionsVersion;
    s.from_positions = positions_flags && (flags & kPositionsFlag);
    s.base_from_positions = positions_flags && (flags & kBasePositionsFlag);
    const bool level_flag =
        version >= kAttributeSectionLevelsVersion && (flags & kLevelPositionsFlag);
    if (level_flag)
      s.level_positions.assign(1, 0); // (read below: the mask follows the ranges)
    s.name = read_string(r.u8());
    const uint32_t want = s.kind == AttributeKind::Normal     ? 3
                          : s.kind == AttributeKind::TexCoord ? 2
                          : s.kind == AttributeKind::Scalar   ? 1
                                                              : s.components;
    const bool bits_ok = s.kind == AttributeKind::Colour ? s.bits == 0
                         : s.kind == AttributeKind::Normal
                             ? s.bits == 0 || (s.bits >= 4 && s.bits <= 16)
                             : s.bits <= 24;
    if (s.components != want || want < 1 || want > 4 ||
        (s.kind == AttributeKind::Colour && want < 3) || !bits_ok || s.name.empty() ||
        flags != descriptor_flags(s) || (s.from_positions && level_flag))
      damaged("attribute '" + s.name + "' has an invalid descriptor");
    if (s.bits && s.kind != AttributeKind::Normal)
      for (uint32_t k = 0; k < s.components; ++k) {
        s.lo.push_back(r.f32());
        s.hi.push_back(r.f32());
      }
    if (level_flag) {
      const uint32_t levels = r.u16();
      if (levels == 0)
        damaged("attribute '" + s.name + "' predicts no level from the positions");
      s.level_positions.assign(levels, 0);
      for (uint32_t l = 0; l < levels; l += 8) {
        const uint8_t byte = r.u8();
        for (uint32_t b = 0; b < 8; ++b)
          if (byte >> b & 1) {
            if (l + b >= levels)
              damaged("attribute '" + s.name + "' has a level mask past its level count");
            s.level_positions[l + b] = 1;
          }
      }
    }
    const uint64_t low = r.u32();
    t.estimated_bytes.push_back(low | uint64_t(r.u32()) << 32);
    t.codes += s.codes();
    t.stored.push_back(std::move(s));
  }
  if (t.codes > kMaxAttributeCodes)
    damaged("too many attribute values per vertex");
  const uint32_t textures = r.u16();
  for (uint32_t i = 0; i < textures; ++i)
    t.texture_files.push_back(read_string(r.u16()));
  const uint32_t n = t.codes;
  if (r.u32() != base_vertices)
    damaged("its vertex count does not match the base mesh");
  const uint32_t bytes = r.u32();
  if (uint64_t(r.position()) + bytes != size)
    damaged("its stream does not fill the section");
  t.base_stream_bytes = bytes;
  RangeDecoder rc(data + r.position(), bytes);
  std::vector<AttributeCodeModels> m = attribute_models(t);
  if (keep_base)
    t.base.resize(size_t(base_vertices) * n);
  std::vector<int64_t> res(n), last(n, 0); // last: the previous vertex's codes
  std::vector<int64_t> lo(n), hi(n);
  for (size_t i = 0, k = 0; i < t.stored.size(); ++i)
    for (uint32_t c = 0; c < t.stored[i].codes(); ++c, ++k)
      code_range(t.stored[i], c, lo[k], hi[k]);
  // The wedge texture coordinate's residuals stay residuals: init_attributes predicts them
  // from the base mesh's connectivity.
  t.wedge_uv = wedge_code(t);
  t.wedge_pending = t.wedge_uv >= 0;
  code_base(
      [&](uint32_t v, uint32_t k) {
        res[k] = get_signed(rc, m[k].classes[attribute_context(m[k], res.data(), k)], m[k].top);
        if (t.wedge_pending && (int(k) == t.wedge_uv || int(k) == t.wedge_uv + 1)) {
          if (res[k] < lo[k] - hi[k] || res[k] > hi[k] - lo[k])
            damaged("a base mesh attribute lies outside its range");
          if (keep_base)
            t.base[size_t(v) * n + k] = res[k];
          return;
        }
        const int64_t c = last[k] + res[k];
        if (c < lo[k] || c > hi[k])
          damaged("a base mesh attribute lies outside its range");
        last[k] = c;
        if (keep_base)
          t.base[size_t(v) * n + k] = c;
      },
      base_vertices, n);
  if (rc.overrun())
    damaged("its stream ends too early");
  return t;
}

std::unique_ptr<AttributeTable> load_attribute_table(const uint8_t *data, const FileLayout &layout,
                                                     bool keep_base) {
  const int i = find_section(layout, kAttributeSectionTag);
  if (i < 0)
    return nullptr;
  const uint8_t *body = section_body(data, layout, size_t(i)); // checks its XXH32
  return std::make_unique<AttributeTable>(read_attributes(
      body, layout.header.sections[size_t(i)].bytes, layout.header.base_vertices, keep_base));
}

void attach_attributes(const AttributeTable &t, const LevelMesh &lm, const AttributeMask &mask,
                       Mesh &out) {
  if (mask.texcoords)
    out.texture_files = t.texture_files;
  if (!keeps_any(t, mask))
    return;
  // (the vertex count of `out`: `lm` may have handed its arrays over, codes excepted)
  const uint32_t nv = static_cast<uint32_t>(out.vertex_count()), n = t.codes;
  if (lm.attr_codes != n || lm.attr.size() != size_t(nv) * n)
    throw Error(Error::Kind::Internal, "internal error: the decoded mesh lacks attribute codes");
  for (size_t i = 0, first = 0; i < t.stored.size(); first += t.stored[i].codes(), ++i) {
    const StoredAttribute &s = t.stored[i];
    if (!keeps_attribute(s.name, s.kind, mask))
      continue;
    VertexAttribute a = described<VertexAttribute>(s);
    if (s.kind == AttributeKind::Colour)
      a.colour.resize(size_t(nv) * s.components);
    else
      a.values.resize(size_t(nv) * s.components);
    for (uint32_t v = 0; v < nv; ++v)
      from_codes(s, &lm.attr[size_t(v) * n + first], a, v);
    out.attributes.push_back(std::move(a));
  }
}

void describe_attributes(const AttributeTable &t, FileInfo &info) {
  info.attributes.clear();
  uint64_t total = 0;
  for (size_t i = 0; i < t.stored.size(); ++i) {
    const StoredAttribute &s = t.stored[i];
    AttributeInfo a = described<AttributeInfo>(s);
    a.bytes = t.estimated_bytes[i];
    total += a.bytes;
    info.attributes.push_back(a);
  }
  info.texture_files = t.texture_files;
  // The level streams and cluster blocks carry the attributes with the geometry: count
  // them apart (the split is the encoder's estimate, as for clustered levels).
  info.geometry_bytes -= std::min(info.geometry_bytes, total);
}

} // namespace pomar
