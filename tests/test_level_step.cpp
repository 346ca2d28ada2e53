// The per-level step (refine/level_step.h): a traversal that throws leaves the mesh and
// the face claims exactly as they were, so the same level can be refined afterwards.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "geometry/quantize.h"
#include "mesh/corner_table.h"
#include "refine/level_step.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

/// A Codec policy that splits the first `splits` vertices it visits (smallest patch: one
/// face, v_from placed on v_to) and throws at visit `throw_at` (never if 0).
struct ScriptedCodec {
  uint32_t splits = 1, throw_at = 0, visits = 0;
  int split_flag(uint32_t, int) {
    if (++visits == throw_at)
      corrupt("scripted failure");
    return visits <= splits;
  }
  bool ranks_patches() const { return false; } // (the version 1-4 symbols)
  uint32_t patch_faces(uint32_t, const Ring &) { return 1; }
  uint32_t patch_placement(const Ring &, uint32_t, const PatchPlacements &) { return 0; }
  void split_symbols(uint32_t, const Ring &, const uint32_t *, SplitSymbols &s) {
    s.s_e = 0;
    s.s_l = 1;
    s.s_r = 0;
  }
  const LevelMesh *mesh = nullptr;
  const NormalPredictor &normal_predictor() const { return normal; }
  NormalPredictor normal; // (the curvature term)
  void geometry(uint32_t v_to, const Prediction &, int32_t position[3]) {
    for (int k = 0; k < 3; ++k)
      position[k] = mesh->q[3 * v_to + k];
  }
  void attributes(const LevelMesh &, const int64_t *, int64_t *) {} // meshes without attributes
  [[noreturn]] void corrupt(const char *what) { throw Error(Error::Kind::DamagedFile, what); }
};

LevelMesh level_mesh(const Mesh &m) {
  LevelMesh lm;
  const Quantizer grid = make_quantizer(m.positions.data(), m.vertex_count(), 12);
  lm.q = quantize(grid, m.positions.data(), m.vertex_count());
  lm.seed_faces = static_cast<uint32_t>(m.triangle_count());
  build_corner_table(m.triangles.data(), m.triangle_count(), m.vertex_count(), lm.ct);
  lm.init_lineage();
  return lm;
}

TEST(LevelStep, ThrowingTraversalReleasesItsClaimsAndAppliesNothing) {
  LevelMesh lm = level_mesh(gen::icosphere(2));
  const std::vector<uint16_t> claims = lm.face_claim;
  const uint32_t vertices = lm.vertex_count(), faces = lm.ct.face_count();
  LevelStep step;

  ScriptedCodec failing; // splits the first vertex (claiming a face), throws at the second
  failing.mesh = &lm;
  failing.throw_at = 2;
  EXPECT_THROW(step.global_level(lm, failing, 1), Error);
  EXPECT_EQ(lm.face_claim, claims);
  EXPECT_EQ(lm.vertex_count(), vertices);
  EXPECT_EQ(lm.ct.face_count(), faces);

  // The same split again: it would find its face still claimed had the step kept it.
  ScriptedCodec again;
  again.mesh = &lm;
  EXPECT_NO_THROW(step.global_level(lm, again, 1));
  EXPECT_EQ(lm.vertex_count(), vertices + 1);
  EXPECT_EQ(lm.ct.face_count(), faces + 2);
  EXPECT_EQ(lm.level_of(vertices), 1u);
}

TEST(LevelStep, FailingCheckReleasesTheClaimsToo) {
  LevelMesh lm = level_mesh(gen::icosphere(2));
  const std::vector<uint16_t> claims = lm.face_claim;
  const uint32_t vertices = lm.vertex_count();
  LevelStep step;
  ScriptedCodec codec;
  codec.mesh = &lm;
  StepCounts seen;
  EXPECT_THROW(step.global_level(lm, codec, 1,
                                 [&](const StepCounts &n) {
                                   seen = n;
                                   throw Error(Error::Kind::DamagedFile, "level table disagrees");
                                 }),
               Error);
  EXPECT_EQ(seen.vertices, vertices + 1u); // what the mesh would have had
  EXPECT_EQ(lm.face_claim, claims);
  EXPECT_EQ(lm.vertex_count(), vertices);
}

} // namespace
} // namespace pomar
