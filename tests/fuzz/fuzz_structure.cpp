// libFuzzer target, structure-aware: the input is not a file but a list of edits applied to
// valid .pomar files that the target encodes at start-up (progressive and clustered, from
// generated meshes). Each edit sets one header field (a size, count, version, flag, level
// entry or cluster header field) to a value chosen inside or beyond its range, truncates the
// image, or changes a byte of a block; then every checksum is recomputed (unless the input
// asks not to) and the image goes through every decoder entry point. Findings: a crash, a
// sanitizer report, an exception other than pomar::Error, a hang, or the layout reader
// accepting a block outside the file (checked here, abort()).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <pomar/limits.h>

#include "support/hostile_files.h"
#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"

namespace {

std::vector<std::vector<uint8_t>> g_images;

std::vector<uint8_t> encode_image(const pomar::Mesh &m, bool progressive, uint32_t clusters) {
  pomar::EncodeOptions o;
  o.progressive = progressive;
  o.clusters = clusters;
  o.bits = 10;
  o.memory_limit = pomar::kNoMemoryLimit;
  return pomar::encode(m, o);
}

/// Reads the input front to back; past its end every read gives 0.
struct Cursor {
  const uint8_t *p;
  size_t n, at = 0;
  uint64_t take(int bytes) {
    uint64_t v = 0;
    for (int k = 0; k < bytes; ++k, ++at)
      v |= uint64_t(at < n ? p[at] : 0) << (8 * k);
    return v;
  }
  bool done() const { return at >= n; }
};

void apply_edit(std::vector<uint8_t> &b, Cursor &in) {
  using namespace pomar::hostile;
  const unsigned op = unsigned(in.take(1));
  if (op % 8 == 6) { // truncate to a position (fraction of the size, in 1/65536)
    b.resize(size_t(b.size() * in.take(2) >> 16));
    return;
  }
  if (op % 8 == 7) { // change one byte anywhere (blocks too)
    if (!b.empty())
      b[size_t(in.take(4)) % b.size()] ^= uint8_t(in.take(1) | 1);
    return;
  }
  const std::vector<Field> fields = header_fields(b);
  const Field &f = fields[size_t(in.take(2)) % fields.size()];
  const std::vector<uint64_t> values = interesting_values(f, b);
  uint64_t v;
  switch (op % 8) {
  case 0:
  case 1:
  case 2: // an interesting value
    v = values[size_t(in.take(1)) % values.size()];
    break;
  case 3: // a small step from the current value
    v = get_le(b, f.at, f.bytes) + uint64_t(int64_t(int8_t(in.take(1))));
    break;
  default: // raw
    v = in.take(f.bytes);
    break;
  }
  put_le(b, f.at, v, f.bytes);
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
  using namespace pomar::gen;
  g_images.push_back(encode_image(icosphere(2), true, 0));
  g_images.push_back(encode_image(icosphere(2), false, 6));
  g_images.push_back(encode_image(torus(12, 8), false, 10));
  g_images.push_back(encode_image(grid_with_holes(8, 2), false, 4));
  // Per-corner texture coordinates and two materials (MATL section, wedge attributes).
  g_images.push_back(encode_image(pomar::with_cube_map_texture(icosphere(2)), false, 4));
  g_images.push_back(encode_image(pomar::with_cube_map_texture(icosphere(2)), true, 0));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  Cursor in{data, size};
  const unsigned head = unsigned(in.take(1));
  std::vector<uint8_t> b = g_images[head % g_images.size()];
  const bool keep_checksums = (head & 0x80) != 0; // else they are recomputed
  for (int edits = 0; edits < 8 && !in.done(); ++edits)
    apply_edit(b, in);
  if (!keep_checksums)
    pomar::hostile::repair_checksums(b);
  if (!pomar::hostile::layout_out_of_bounds(b).empty())
    std::abort(); // the layout reader accepted a block outside the file
  // An exact-size copy, so that ASan sees a read one byte past the image.
  std::vector<uint8_t> exact(b.begin(), b.end());
  exact.shrink_to_fit();
  pomar::hostile::exercise_decoders(exact.data(), exact.size());
  return 0;
}
