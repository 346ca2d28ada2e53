// pomar_hostile_files: damaged and hostile .pomar files made from a valid one, every
// checksum recomputed where the edit would break it (tests/support/hostile_files.h), for
// bench/truncation_bench.py and tests/e2e/hostile_info_test.sh.
//
//   pomar_hostile_files shift-index IN OUT CLUSTER DELTA
//       the cluster index with CLUSTER's block DELTA bytes longer and the last block DELTA
//       shorter (the same total): every block after CLUSTER starts DELTA bytes off, its
//       8-bit check computed on the intact block (a misaligned index, as a buggy writer
//       or a hostile one makes it). IN may be truncated.
//   pomar_hostile_files crafted IN OUTDIR
//       the hostile cases of docs/robustness.md's bounds table, each NAME.pomar, written
//       from a random-access file IN (and its progressive counterpart, see below); prints
//       one name per line.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "attributes/attribute_section.h"
#include "format/file_format.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "support/hostile_files.h"

namespace {

using namespace pomar;
using hostile::get_le;
using hostile::put_le;

std::vector<uint8_t> shift_index(const std::vector<uint8_t> &file, uint32_t cluster,
                                 int64_t delta) {
  const FileLayout L = read_layout(file.data(), file.size(), file.size(), true);
  ClusterIndex index = read_cluster_index(file.data() + L.index_offset, L);
  const size_t n = index.size.size();
  if (cluster + 1 >= n)
    throw Error(Error::Kind::Usage, "cluster " + std::to_string(cluster) + " is the last one");
  if (int64_t(index.size[n - 1]) < delta || int64_t(index.size[cluster]) < -delta)
    throw Error(Error::Kind::Usage, "blocks too small for that shift");
  index.size[cluster] = uint32_t(int64_t(index.size[cluster]) + delta);
  index.size[n - 1] = uint32_t(int64_t(index.size[n - 1]) - delta);
  return hostile::with_cluster_index(file, index);
}

/// A level table that grows from the base counts towards (vertices, faces) like vertex
/// splits (each level adds at least one vertex and at most doubles them), the global
/// levels' block sizes kept; `vertices` is lowered to what the level count can reach.
void grow_levels(std::vector<uint8_t> &b, uint64_t vertices, uint64_t faces) {
  const uint32_t levels = uint32_t(get_le(b, 48, 4));
  uint64_t nv = get_le(b, 40, 4), nf = get_le(b, 44, 4);
  vertices = std::min<uint64_t>(vertices, nv << std::min<uint32_t>(levels, 40));
  for (uint32_t i = 0; i < levels; ++i) {
    const uint64_t left = levels - 1 - i; // levels after this one, each adding a vertex
    const uint64_t v = std::max(nv + 1, std::min(2 * nv, vertices - left));
    const uint64_t f = i + 1 == levels ? std::max(faces, nf) : std::max<uint64_t>(nf, 2 * v);
    const size_t e = kFixedHeaderBytes + kLevelEntryBytes * i;
    put_le(b, e, v, 4);
    put_le(b, e + 4, f, 4);
    nv = v;
    nf = f;
  }
  put_le(b, 32, nv, 4);
  put_le(b, 36, nf, 4);
}

struct Case {
  std::string name;
  std::vector<uint8_t> image;
};

std::vector<Case> crafted(const std::vector<uint8_t> &clustered,
                          const std::vector<uint8_t> &progressive) {
  std::vector<Case> out;
  auto add = [&](const std::string &name, std::vector<uint8_t> b) {
    hostile::repair_checksums(b);
    out.push_back({name, std::move(b)});
  };
  const FileLayout C = read_layout(clustered.data(), clustered.size());
  const FileLayout P = read_layout(progressive.data(), progressive.size());
  // The largest counts the size checks let through: 512 vertices per byte of the file.
  {
    std::vector<uint8_t> b = progressive;
    const uint64_t v = 512 * uint64_t(b.size());
    grow_levels(b, v, 2 * v - 4);
    add("huge_counts", b);
  }
  {
    std::vector<uint8_t> b = progressive;
    grow_levels(b, uint64_t(1) << 31, uint64_t(1) << 31);
    add("vertices_2_31", b);
  }
  {
    std::vector<uint8_t> b = clustered;
    put_le(b, 32, uint64_t(1) << 31, 4);
    put_le(b, 36, uint64_t(1) << 31, 4);
    add("header_2_31_vertices", b);
  }
  // The base block all zeros (its checksum right), with the most base faces its size allows
  // (4 per byte + 64) and three vertices a face: what the count checks let through.
  for (const bool most : {false, true}) {
    std::vector<uint8_t> b = progressive;
    std::fill(b.begin() + long(P.base_offset),
              b.begin() + long(P.base_offset + P.header.base_bytes), 0);
    if (most) {
      const uint64_t f = 4 * uint64_t(P.header.base_bytes) + 64, v = 3 * f;
      put_le(b, 40, v, 4);
      put_le(b, 44, f, 4);
      grow_levels(b, 2 * v, 4 * f);
    }
    add(most ? "zero_base_most_counts" : "zero_base", b);
  }
  {
    // A version 1 file of almost 1 MB: a base block of zeros claiming the most faces it may
    // hold, one level of no data.
    const uint64_t bytes = 1000000 - 200, f = 4 * bytes + 64, v = 3 * f;
    std::vector<uint8_t> b(kFixedHeaderBytes + kLevelEntryBytes + 4 + bytes, 0);
    std::copy(progressive.begin(), progressive.begin() + 8, b.begin()); // the signature
    put_le(b, 8, kFormatVersion, 2);
    put_le(b, 12, get_le(progressive, 12, 1), 1);                                  // bits
    std::copy(progressive.begin() + 16, progressive.begin() + 32, b.begin() + 16); // box
    put_le(b, 32, 2 * v, 4);
    put_le(b, 36, 2 * f, 4);
    put_le(b, 40, v, 4);
    put_le(b, 44, f, 4);
    put_le(b, 48, 1, 4);
    put_le(b, 52, bytes, 4);
    put_le(b, kFixedHeaderBytes, 2 * v, 4);
    put_le(b, kFixedHeaderBytes + 4, 2 * f, 4);
    add("zero_base_1mb", b);
  }
  // A structurally valid base mesh as large as its block allows: separate triangles, every
  // vertex at one position (the deltas cost almost nothing), with four colour codes and a
  // scalar per vertex (all zero, almost free too) in its ATTR section: a header, a base mesh
  // and a section that agree, each decoded whole by info. The same with a wedge texture
  // coordinate ("pomar:corner texcoord", the seam cut's, predicted from the base mesh's
  // neighbours) instead: info --check builds that base mesh to resolve it.
  for (const bool wedges : {false, true}) {
    const uint32_t f = 1'000'000, v = 3 * f;
    BaseMesh base;
    base.q.assign(size_t(v) * 3, 0);
    for (uint32_t i = 0; i < v; ++i)
      base.triangles.push_back(i);
    const std::vector<uint8_t> block = pack_base_mesh(base, 12);
    Mesh m;
    m.positions.assign(size_t(v) * 3, 0.0f);
    m.triangles = base.triangles;
    if (wedges) {
      VertexAttribute uv;
      uv.kind = AttributeKind::TexCoord;
      uv.name = "pomar:corner texcoord";
      uv.components = 2;
      uv.values.assign(size_t(v) * 2, 0.0f);
      m.attributes.push_back(uv);
    } else {
      VertexAttribute colour;
      colour.kind = AttributeKind::Colour;
      colour.name = "colour";
      colour.components = 4;
      colour.colour.assign(size_t(v) * 4, 0);
      m.attributes.push_back(colour);
      VertexAttribute quality;
      quality.kind = AttributeKind::Scalar;
      quality.name = "quality";
      quality.values.assign(v, 0.0f);
      m.attributes.push_back(quality);
    }
    AttributeTable table = plan_attributes(m, AttributeOptions());
    std::vector<uint32_t> order(v);
    for (uint32_t i = 0; i < v; ++i)
      order[i] = i;
    table.base = attribute_codes(m, table, AttributeOptions(), order);
    FileHeader h;
    h.grid.bits = 12;
    h.grid.extent = 1;
    h.base_vertices = v;
    h.base_faces = f;
    h.vertices = 2 * v;
    h.faces = 2 * f;
    h.levels.push_back({2 * v, 2 * f, 0, 0, 0});
    std::vector<uint8_t> b =
        write_file(h, block, {{}}, {}, {}, {{kAttributeSectionTag, 0, write_attributes(table, v)}});
    add(wedges ? "big_base_wedges" : "big_base_attributes", b);
  }
  // Section tables: the count at its limit (64, the entries read from the bytes after
  // the header) and beyond it; a section claiming far more bytes than the file has.
  if (hostile::section_table_at(clustered)) {
    const size_t t = hostile::section_table_at(clustered);
    for (const uint64_t count : {uint64_t(kMaxSections), uint64_t(0xFFFFFFFFu)}) {
      std::vector<uint8_t> b = clustered;
      put_le(b, t, count, 4);
      add(count == kMaxSections ? "sections_64" : "sections_2_32", b);
    }
    std::vector<uint8_t> b = clustered;
    put_le(b, t + 4 + 8, uint64_t(1) << 40, 8); // the first section's size
    add("section_huge", b);
  }
  // The cluster count as large as the index may hold, the index all zeros.
  {
    std::vector<uint8_t> b = clustered;
    std::fill(b.begin() + long(C.index_offset),
              b.begin() + long(C.index_offset + C.header.index_bytes), 0);
    add("zero_index", b);
  }
  // The cluster index shifted: misaligned blocks.
  add("shifted_index", shift_index(clustered, 0, 1));
  return out;
}

std::vector<uint8_t> read(const char *path) { return read_file(path); }

void write(const std::string &path, const std::vector<uint8_t> &b) {
  write_file_atomic(path, b.data(), b.size());
}

} // namespace

int main(int argc, char **argv) {
  try {
    const std::string cmd = argc > 1 ? argv[1] : "";
    if (cmd == "shift-index" && argc == 6) {
      write(argv[3],
            shift_index(read(argv[2]), uint32_t(std::stoul(argv[4])), std::stoll(argv[5])));
      return 0;
    }
    if (cmd == "crafted" && argc == 5) {
      for (const Case &c : crafted(read(argv[2]), read(argv[3]))) {
        if (c.image.size() >= 1000000)
          throw Error(Error::Kind::Internal, c.name + " is not under 1 MB");
        write(std::string(argv[4]) + "/" + c.name + ".pomar", c.image);
        std::printf("%s\n", c.name.c_str());
      }
      return 0;
    }
    std::fprintf(stderr, "usage: pomar_hostile_files shift-index IN OUT CLUSTER DELTA\n"
                         "       pomar_hostile_files crafted CLUSTERED PROGRESSIVE OUTDIR\n");
    return 2;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar_hostile_files: %s\n", e.what());
    return 1;
  }
}
