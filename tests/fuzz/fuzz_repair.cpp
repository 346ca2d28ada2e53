// libFuzzer target: pomar::make_manifold on arbitrary triangle soups, then the codec.
// The bytes are read as: vertex count (1 byte, 1..64), then triangles of three 1-byte
// vertex indices (taken modulo the vertex count, so faces repeating a vertex, duplicates,
// non-manifold edges and vertices, and inconsistent orientation are all common).
// Properties (a violation aborts, which libFuzzer reports): after the repair the mesh is
// accepted by the encoder unless it has no triangles left, and it decodes losslessly;
// a second repair changes nothing.
#include <pomar/pomar.h>
#include <pomar/repair.h>

#include <algorithm>
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
    const int r = int(std::min_element(t, t + 3) - t);
    std::vector<float> row;
    for (int k = 0; k < 3; ++k)
      row.insert(row.end(), t[(r + k) % 3].begin(), t[(r + k) % 3].end());
    out.push_back(row);
  }
  std::sort(out.begin(), out.end());
  return out;
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 4 || size > 3 * 512 + 1)
    return 0;
  const uint32_t nv = 1 + data[0] % 64;
  pomar::Mesh mesh;
  // Distinct positions on a small grid (repair never moves a vertex; the codec's grid
  // keeps 12-bit positions of this grid exact).
  for (uint32_t v = 0; v < nv; ++v) {
    mesh.positions.push_back(float(v % 4));
    mesh.positions.push_back(float((v / 4) % 4));
    mesh.positions.push_back(float(v / 16));
  }
  for (size_t i = 1; i + 3 <= size; i += 3)
    for (int k = 0; k < 3; ++k)
      mesh.triangles.push_back(data[i + k] % nv);

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
