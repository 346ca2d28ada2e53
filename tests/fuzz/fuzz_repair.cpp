// libFuzzer target: pomar::make_manifold on arbitrary triangle soups, then the codec.
// The bytes are read as: vertex count (1 byte, 1..64), then triangles of three 1-byte
// vertex indices (taken modulo the vertex count, so faces repeating a vertex, duplicates,
// non-manifold edges and vertices, and inconsistent orientation are all common).
// The top bit of the first byte puts vertices on shared positions (v % 8), the next one
// asks for the input vertex order (keep_order).
// Properties (a violation aborts, which libFuzzer reports): after the repair the mesh is
// accepted by the encoder unless it has no triangles left, and it decodes losslessly;
// a second repair changes nothing; and the soup itself (cut + stored corrections) encodes
// by default and decodes to exactly the soup: its vertex count, every vertex on its grid
// position, its oriented faces as a multiset (duplicates and faces repeating a vertex
// included), vertices in input order with keep_order.
#include <pomar/pomar.h>
#include <pomar/repair.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {
[[noreturn]] void violated(const char *what) {
  std::fprintf(stderr, "fuzz_repair: property violated: %s\n", what);
  std::abort();
}

/// Sorted (position triple) per triangle, rotation-normalised: compares meshes whatever
/// their vertex order.
std::vector<std::vector<float>> triangles_by_position(const pomar::Mesh &m) {
  std::vector<std::vector<float>> out;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    std::vector<float> t[3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[3 * f + k];
      t[k] = {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
    }
    // The smallest of the three rotations (two corners may share a position).
    std::vector<float> best;
    for (int r = 0; r < 3; ++r) {
      std::vector<float> row;
      for (int k = 0; k < 3; ++k)
        row.insert(row.end(), t[(r + k) % 3].begin(), t[(r + k) % 3].end());
      if (r == 0 || row < best)
        best = row;
    }
    out.push_back(best);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// The oriented faces of `m` as a sorted multiset of index triples (smallest rotation),
/// vertex v renamed to name[v].
std::vector<std::array<uint32_t, 3>> faces(const pomar::Mesh &m, const std::vector<uint32_t> &name) {
  std::vector<std::array<uint32_t, 3>> out;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    const uint32_t a = name[m.triangles[3 * f]], b = name[m.triangles[3 * f + 1]],
                   c = name[m.triangles[3 * f + 2]];
    out.push_back(std::min({std::array<uint32_t, 3>{a, b, c}, std::array<uint32_t, 3>{b, c, a},
                            std::array<uint32_t, 3>{c, a, b}}));
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// The soup as it is: encoded by default (the cut and what it changed are stored), decoded
/// in full, it must be exactly the soup.
void check_exact(const pomar::Mesh &soup, bool keep_order) {
  bool any = false; // a face not repeating a vertex: something to code
  for (size_t c = 0; c < soup.triangles.size(); c += 3)
    any |= soup.triangles[c] != soup.triangles[c + 1] &&
           soup.triangles[c + 1] != soup.triangles[c + 2] && soup.triangles[c] != soup.triangles[c + 2];
  pomar::EncodeOptions options;
  options.keep_order = keep_order;
  pomar::EncodeReport report;
  std::vector<uint8_t> file;
  try {
    file = pomar::encode(soup, options, &report);
  } catch (const pomar::Error &e) {
    if (any) {
      std::fprintf(stderr, "fuzz_repair: encode refused the soup: %s\n", e.what());
      violated("a soup with a valid face is not encodable");
    }
    return;
  }
  if (!any)
    violated("a soup without a valid face was encoded");
  const pomar::Mesh out = pomar::decode(file.data(), file.size());
  if (out.vertex_count() != soup.vertex_count() || out.triangle_count() != soup.triangle_count())
    violated("the decoded soup has other counts");
  const std::vector<uint32_t> &to_input = report.decoded_to_input;
  if (to_input.size() != out.vertex_count())
    violated("decoded_to_input does not cover the decoded vertices");
  std::vector<uint32_t> seen(soup.vertex_count(), 0), identity(soup.vertex_count());
  const pomar::Quantizer grid = pomar::inspect(file.data(), file.size()).grid;
  for (uint32_t v = 0; v < out.vertex_count(); ++v) {
    identity[v] = v;
    const uint32_t i = to_input[v];
    if (i >= soup.vertex_count() || seen[i]++)
      violated("decoded_to_input is not a permutation");
    if (keep_order && i != v)
      violated("keep_order: a vertex is not in its input place");
    for (int k = 0; k < 3; ++k)
      if (out.positions[3 * v + k] != grid.dequantize(k, grid.quantize(k, soup.positions[3 * i + k])))
        violated("a decoded vertex is not on its input vertex's grid position");
  }
  if (faces(out, to_input) != faces(soup, identity))
    violated("the decoded faces are not the soup's");
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 4 || size > 3 * 512 + 1)
    return 0;
  const uint32_t nv = 1 + data[0] % 64;
  const bool shared_positions = (data[0] & 0x80) != 0, keep_order = (data[0] & 0x40) != 0;
  pomar::Mesh mesh;
  // Positions on a small grid (repair never moves a vertex; the codec's grid keeps 12-bit
  // positions of this grid exact), distinct unless shared_positions.
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t p = shared_positions ? v % 8 : v;
    mesh.positions.push_back(float(p % 4));
    mesh.positions.push_back(float((p / 4) % 4));
    mesh.positions.push_back(float(p / 16));
  }
  for (size_t i = 1; i + 3 <= size; i += 3)
    for (int k = 0; k < 3; ++k)
      mesh.triangles.push_back(data[i + k] % nv);

  check_exact(mesh, keep_order);

  pomar::RepairReport report;
  try {
    report = pomar::make_manifold(mesh);
  } catch (const pomar::Error &) {
    violated("make_manifold threw on in-range indices");
  }
  (void)report.summary();
  pomar::Mesh again = mesh;
  if (pomar::make_manifold(again).changed())
    violated("a second repair changed the mesh");
  if (mesh.triangle_count() == 0)
    return 0; // everything was degenerate or duplicate: nothing to encode
  std::vector<uint8_t> file;
  try {
    file = pomar::encode(mesh);
  } catch (const pomar::Error &e) {
    std::fprintf(stderr, "fuzz_repair: encode refused the repaired mesh: %s\n", e.what());
    violated("the repaired mesh is not encodable");
  }
  const pomar::Mesh decoded = pomar::decode(file.data(), file.size());
  // Compare on the file's grid, where the encoder put every vertex.
  const pomar::Quantizer grid = pomar::inspect(file.data(), file.size()).grid;
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const int axis = int(i % 3);
    mesh.positions[i] = grid.dequantize(axis, grid.quantize(axis, mesh.positions[i]));
  }
  if (triangles_by_position(decoded) != triangles_by_position(mesh))
    violated("the repaired mesh does not round-trip");
  return 0;
}
