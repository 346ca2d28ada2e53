// The ATTR section: descriptors, per-cluster counts and one residual stream per attribute
// (byte layout: docs/format.md, "ATTR section").
#include "attributes/attribute_section.h"

#include <algorithm>
#include <array>
#include <string>

#include "entropy/models.h"
#include "format/bit_io.h"
#include "format/file_format.h"
#include "refine/level_traversal.h"

namespace pomar {
namespace {

constexpr int kResidualContexts = 6; // by the bit length of the previous code's residual

/// Adaptive models of one attribute's residuals: per code component, per context.
struct ResidualModels {
  explicit ResidualModels(uint32_t codes)
      : classes(codes * kResidualContexts, FrequencyModel(kMagnitudeSymbols)), top(codes) {}
  std::vector<FrequencyModel> classes;
  std::vector<std::array<BitModel, kMagnitudeSymbols>> top;
  static int context(uint32_t k, const int64_t *r) {
    if (k == 0)
      return 0;
    const int n = bit_length(static_cast<uint64_t>(r[k - 1] < 0 ? -r[k - 1] : r[k - 1]));
    return std::min(n, kResidualContexts - 1);
  }
};

[[noreturn]] void damaged(const std::string &what) {
  throw Error("damaged .pomar file: ATTR section: " + what);
}

/// Attribute index of every vertex of lm (see attribute_section.h).
uint32_t attribute_index(const LevelMesh &lm, uint32_t v, uint32_t clusters,
                         const std::vector<uint32_t> &start) {
  if (clusters == 0 || v < clusters)
    return v;
  const uint32_t c = lm.cluster_of(v), local = lm.local[v];
  if (c >= clusters || local == 0 || local > start[c + 1] - start[c])
    damaged("vertex " + std::to_string(v) + " (cluster " + std::to_string(c) + ", rank " +
            std::to_string(local) + ") has no attributes");
  return clusters + start[c] + local - 1;
}

/// The prediction of vertex v's codes: its parent's (base vertices: the previous one's).
const int64_t *prediction(const LevelMesh &lm, uint32_t v, const std::vector<int64_t> &codes,
                          uint32_t n, const int64_t *zero) {
  const uint32_t p = lm.parent[v];
  if (p != v)
    return &codes[size_t(p) * n];
  return v ? &codes[size_t(v - 1) * n] : zero;
}

} // namespace

std::vector<uint8_t> write_attributes(const Mesh &mesh, const AttributeOptions &options,
                                      const LevelMesh &lm,
                                      const std::vector<uint32_t> &decoded_to_input,
                                      uint32_t clusters) {
  std::vector<const VertexAttribute *> kept;
  for (const VertexAttribute &a : mesh.attributes)
    if (options.keep.keeps(a.kind))
      kept.push_back(&a);
  if (kept.empty() && (mesh.texture_files.empty() || !options.keep.texcoords))
    return {};
  if (kept.size() > 255)
    throw Error("at most 255 attributes can be stored (the mesh has " +
                std::to_string(kept.size()) + ")");
  const uint32_t nv = lm.vertex_count();
  std::vector<uint8_t> out;
  ByteWriter w(out);
  w.u8(kAttributeSectionVersion);
  w.u8(static_cast<uint8_t>(kept.size()));
  std::vector<StoredAttribute> stored;
  for (const VertexAttribute *a : kept) {
    stored.push_back(describe(*a, options));
    const StoredAttribute &s = stored.back();
    w.u8(static_cast<uint8_t>(s.kind));
    w.u8(static_cast<uint8_t>(s.components));
    w.u8(static_cast<uint8_t>(s.bits));
    w.u8(static_cast<uint8_t>(s.name.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(s.name.data()), s.name.size());
    for (size_t k = 0; k < s.lo.size(); ++k) {
      w.f32(s.lo[k]);
      w.f32(s.hi[k]);
    }
  }
  const std::vector<std::string> none;
  const std::vector<std::string> &textures = options.keep.texcoords ? mesh.texture_files : none;
  if (textures.size() > 0xFFFF)
    throw Error("too many texture files (" + std::to_string(textures.size()) + ")");
  w.u16(static_cast<uint16_t>(textures.size()));
  for (const std::string &t : textures) {
    if (t.size() > 0xFFFF)
      throw Error("texture file name too long: " + t.substr(0, 64) + "...");
    w.u16(static_cast<uint16_t>(t.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(t.data()), t.size());
  }
  w.u32(nv);
  w.u32(clusters);
  std::vector<uint32_t> start;
  if (clusters) {
    std::vector<uint32_t> count(clusters, 0);
    for (uint32_t v = clusters; v < nv; ++v)
      count[lm.cluster_of(v)] = std::max(count[lm.cluster_of(v)], lm.local[v]);
    start.assign(clusters + 1, 0);
    for (uint32_t c = 0; c < clusters; ++c) {
      w.u32(count[c]);
      start[c + 1] = start[c] + count[c];
    }
    if (start[clusters] != nv - clusters)
      throw Error("internal encoder error: cluster vertex counts do not add up");
  }
  std::vector<uint32_t> index(nv);
  for (uint32_t v = 0; v < nv; ++v)
    index[v] = attribute_index(lm, v, clusters, start);

  std::vector<std::vector<uint8_t>> streams;
  for (size_t i = 0; i < kept.size(); ++i) {
    const StoredAttribute &s = stored[i];
    const uint32_t n = s.codes();
    std::vector<int64_t> codes(size_t(nv) * n), residual(size_t(nv) * n);
    for (uint32_t v = 0; v < nv; ++v)
      to_codes(s, *kept[i], decoded_to_input[v], &codes[size_t(v) * n]);
    const int64_t zero[4] = {0, 0, 0, 0};
    for (uint32_t v = 0; v < nv; ++v) {
      const int64_t *p = prediction(lm, v, codes, n, zero);
      for (uint32_t k = 0; k < n; ++k)
        residual[size_t(index[v]) * n + k] = codes[size_t(v) * n + k] - p[k];
    }
    streams.emplace_back();
    RangeEncoder rc(&streams.back());
    ResidualModels m(n);
    for (size_t j = 0; j < residual.size(); j += n)
      for (uint32_t k = 0; k < n; ++k)
        put_signed(rc, m.classes[k * kResidualContexts + ResidualModels::context(k, &residual[j])],
                   m.top[k].data(), residual[j + k]);
    rc.finish();
  }
  for (const auto &s : streams)
    w.u32(static_cast<uint32_t>(s.size()));
  for (const auto &s : streams)
    w.bytes(s.data(), s.size());
  return out;
}

AttributeTable read_attributes(const uint8_t *data, size_t size, uint32_t vertices,
                               uint32_t clusters, bool decode, const AttributeMask &mask) {
  ByteReader r(data, size, "damaged .pomar file: ATTR section");
  AttributeTable t;
  const uint8_t version = r.u8();
  if (version != kAttributeSectionVersion)
    throw Error("ATTR section version " + std::to_string(version) +
                " is not supported (this pomar reads version 1)");
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
    s.name = read_string(r.u8());
    const uint32_t want = s.kind == AttributeKind::Normal     ? 3
                          : s.kind == AttributeKind::TexCoord ? 2
                          : s.kind == AttributeKind::Scalar   ? 1
                                                              : s.components;
    const int max_bits = s.kind == AttributeKind::Normal ? 16 : 24;
    if (s.components != want || (s.kind == AttributeKind::Colour && (want < 3 || want > 4)) ||
        (s.kind == AttributeKind::Colour ? s.bits != 0
                                         : s.bits > max_bits ||
                                               (s.kind == AttributeKind::Normal && s.bits &&
                                                s.bits < 4)))
      damaged("attribute '" + s.name + "' has an invalid descriptor");
    if (s.bits && s.kind != AttributeKind::Normal && s.kind != AttributeKind::Colour)
      for (uint32_t k = 0; k < s.components; ++k) {
        s.lo.push_back(r.f32());
        s.hi.push_back(r.f32());
      }
    t.stored.push_back(std::move(s));
  }
  const uint32_t textures = r.u16();
  for (uint32_t i = 0; i < textures; ++i)
    t.texture_files.push_back(read_string(r.u16()));
  t.vertices = r.u32();
  t.clusters = r.u32();
  if (t.vertices != vertices || t.clusters != clusters)
    damaged("its vertex or cluster count does not match the header");
  if (clusters) {
    t.cluster_start.assign(clusters + 1, 0);
    for (uint32_t c = 0; c < clusters; ++c) {
      const uint64_t next = uint64_t(t.cluster_start[c]) + r.u32();
      if (next > vertices - clusters)
        damaged("its cluster vertex counts exceed the vertex count");
      t.cluster_start[c + 1] = static_cast<uint32_t>(next);
    }
    if (t.cluster_start[clusters] != vertices - clusters)
      damaged("its cluster vertex counts do not add up to the vertex count");
  }
  uint64_t offset = r.position() + 4 * uint64_t(count);
  std::vector<uint64_t> stream_offset;
  for (uint32_t i = 0; i < count; ++i) {
    t.stream_bytes.push_back(r.u32());
    stream_offset.push_back(offset);
    offset += t.stream_bytes.back();
  }
  if (offset != size)
    damaged("its streams do not fill the section");
  std::vector<StoredAttribute> kept;
  std::vector<uint64_t> kept_bytes;
  for (uint32_t i = 0; i < count; ++i) {
    if (!mask.keeps(t.stored[i].kind))
      continue;
    kept.push_back(t.stored[i]);
    kept_bytes.push_back(t.stream_bytes[i]);
    if (!decode)
      continue;
    const StoredAttribute &s = t.stored[i];
    const uint32_t n = s.codes();
    std::vector<int64_t> res(size_t(vertices) * n);
    RangeDecoder rc(data + stream_offset[i], t.stream_bytes[i]);
    ResidualModels m(n);
    for (size_t j = 0; j < res.size(); j += n)
      for (uint32_t k = 0; k < n; ++k)
        res[j + k] = get_signed(
            rc, m.classes[k * kResidualContexts + ResidualModels::context(k, &res[j])],
            m.top[k].data());
    if (rc.overrun())
      damaged("the stream of attribute '" + s.name + "' ends too early");
    t.residuals.push_back(std::move(res));
  }
  if (!mask.texcoords)
    t.texture_files.clear();
  t.stored = std::move(kept);
  t.stream_bytes = std::move(kept_bytes);
  t.decoded = decode;
  return t;
}

void attach_attributes(const AttributeTable &t, const LevelMesh &lm, Mesh &out) {
  out.texture_files = t.texture_files;
  if (!t.decoded)
    return;
  const uint32_t nv = lm.vertex_count();
  if (nv > t.vertices)
    damaged("the mesh has more vertices than the section");
  std::vector<uint32_t> index(nv);
  for (uint32_t v = 0; v < nv; ++v)
    index[v] = attribute_index(lm, v, t.clusters, t.cluster_start);
  for (size_t i = 0; i < t.stored.size(); ++i) {
    const StoredAttribute &s = t.stored[i];
    const uint32_t n = s.codes();
    VertexAttribute a;
    a.kind = s.kind;
    a.name = s.name;
    a.components = s.components;
    a.bits = s.bits;
    a.bound = s.bound();
    if (s.kind == AttributeKind::Colour)
      a.colour.resize(size_t(nv) * s.components);
    else
      a.values.resize(size_t(nv) * s.components);
    int64_t lo[4], hi[4];
    for (uint32_t k = 0; k < n; ++k)
      code_range(s, k, lo[k], hi[k]);
    std::vector<int64_t> codes(size_t(nv) * n);
    const int64_t zero[4] = {0, 0, 0, 0};
    const std::vector<int64_t> &res = t.residuals[i];
    for (uint32_t v = 0; v < nv; ++v) {
      const int64_t *p = prediction(lm, v, codes, n, zero);
      int64_t *c = &codes[size_t(v) * n];
      for (uint32_t k = 0; k < n; ++k) {
        c[k] = p[k] + res[size_t(index[v]) * n + k];
        if (c[k] < lo[k] || c[k] > hi[k])
          damaged("attribute '" + s.name + "' of vertex " + std::to_string(v) +
                  " is out of range");
      }
      from_codes(s, c, a, v);
    }
    out.attributes.push_back(std::move(a));
  }
}

void describe_attributes(const AttributeTable &t, FileInfo &info) {
  info.attributes.clear();
  for (size_t i = 0; i < t.stored.size(); ++i) {
    const StoredAttribute &s = t.stored[i];
    AttributeInfo a;
    a.kind = s.kind;
    a.name = s.name;
    a.components = s.components;
    a.bits = s.bits;
    a.bound = s.bound();
    a.bytes = t.stream_bytes[i];
    info.attributes.push_back(a);
  }
  info.texture_files = t.texture_files;
}

} // namespace pomar

namespace pomar {

std::unique_ptr<AttributeTable> load_attribute_table(const uint8_t *data, const FileLayout &layout,
                                                     bool decode, const AttributeMask &mask) {
  if (!mask.colour && !mask.normals && !mask.scalars && !mask.texcoords)
    return nullptr;
  const int i = find_section(layout, kAttributeSectionTag);
  if (i < 0)
    return nullptr;
  const uint8_t *body = section_body(data, layout, size_t(i)); // checks its XXH32
  const FileHeader &h = layout.header;
  return std::make_unique<AttributeTable>(
      read_attributes(body, layout.header.sections[size_t(i)].bytes, h.vertices,
                      h.clustered() ? h.clusters : 0, decode, mask));
}

} // namespace pomar
