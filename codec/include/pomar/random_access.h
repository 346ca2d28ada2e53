// Random access to clustered .pomar files (paper sections 5.2 and 6): decode the base
// clustered mesh, then any clusters at any levels, reading only the blocks they need, and
// refine further later without starting over.
//
//   pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>("dragon.pomar"));
//   d.want_sphere({0.01f, 0.12f, 0.0f}, 0.02f);   // finest level by default
//   d.update();                                   // completes the level map, decodes
//   pomar::Mesh m = d.mesh();                     // + d.vertex_cluster(), d.vertex_level()
//   d.want_cluster(17, d.finest_level());  d.update();   // delta refinement
//
// Threads and ownership: a SelectiveDecoder owns its ByteSource and calls it only from
// inside its own member functions (from its own threads too, one call at a time: see
// SelectiveOptions::threads); use each decoder (and each source) from one thread at a
// time (several decoders on several threads are independent, also on the same file).
// The const members (info, levels, mesh, ...) read state only and may be called
// concurrently with each other, not with update() or a want_*() call.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

/// Where the bytes of a .pomar file come from: a file, memory, or (one day) a network
/// range request. The decoder asks for the header and global part once, then for single
/// cluster blocks.
class ByteSource {
public:
  virtual ~ByteSource() = default;
  virtual uint64_t size() const = 0;
  /// Read exactly n bytes at offset into out; throws pomar::Error on failure.
  virtual void read(uint64_t offset, size_t n, uint8_t *out) = 0;
};

/// Bytes in memory. Does not copy them: `data` must stay valid and unchanged for the
/// source's lifetime (and so for the lifetime of a SelectiveDecoder that owns it).
class MemorySource : public ByteSource {
public:
  MemorySource(const uint8_t *data, size_t size) : data_(data), size_(size) {}
  uint64_t size() const override { return size_; }
  void read(uint64_t offset, size_t n, uint8_t *out) override;

private:
  const uint8_t *data_;
  size_t size_;
};

/// A file, opened by the constructor (throws pomar::Error naming the path) and read with
/// fseek/fread; the file should not change while it is open.
class FileSource : public ByteSource {
public:
  explicit FileSource(const std::string &path);
  ~FileSource() override;
  FileSource(const FileSource &) = delete;
  FileSource &operator=(const FileSource &) = delete;
  uint64_t size() const override { return size_; }
  void read(uint64_t offset, size_t n, uint8_t *out) override;

private:
  std::string path_;
  std::FILE *file_ = nullptr;
  uint64_t size_ = 0;
};

struct SelectiveOptions {
  /// update() decodes around damaged or missing cluster blocks instead of failing (see
  /// SelectiveDecoder::damaged()); the file may be truncated after its global part; every
  /// block is read whole so that its check is verified before it is decoded.
  bool skip_damaged = false;
  /// Bytes the decoding may need (0 = automatic, UINT64_MAX = do not check; see
  /// pomar/limits.h): the constructor checks the base clustered mesh (progressive files:
  /// the base mesh), update() each level map before decoding it (pomar::Error with
  /// Kind::MemoryLimit, the mesh as it was). A map's counts are estimated from the level
  /// table: exact when every cluster is at one level; for a region, the base clustered
  /// mesh plus 1.3 times the average growth of a cluster to each refined cluster's level
  /// (the clusters of a scan differ), at most the whole mesh at the map's finest level.
  uint64_t memory_limit = 0;
  /// Which stored attributes mesh() returns (AttributeMask::none(): none). Their codes
  /// come with the positions, block by block: with none kept they are read past (no
  /// storage, no prediction), otherwise decoded and stored.
  AttributeMask attributes;
  /// Threads update() decodes the clusters of a level on (0 = the cores this process may
  /// run on; at most 8, as DecodeOptions::threads); the mesh is the same for any number.
  /// With more than one, the ByteSource is called from the decoder's threads, one call at
  /// a time.
  unsigned threads = 0;
  /// With threads > 1, a clustered level with less work than this (its vertices per
  /// cluster times the clusters to refine, from the level table) is decoded on the calling
  /// thread: on small levels the parallel phases cost more than they save. 0: every level
  /// on the threads. The mesh does not depend on it.
  uint32_t min_parallel_vertices = 4096;
  /// Keep SelectiveDecoder::numbered_levels() (24 bytes per cluster level decoded).
  bool record_numbering = false;
};

/// A camera for view-dependent decoding, as the web client describes it (camera.js viewOf):
/// the eye, the view-projection matrix (column-major, clip = view_proj * [x y z 1], OpenGL
/// clip volume -w <= x, y, z <= w), the vertical field of view, the viewport in pixels and
/// the near distance (clusters nearer than it are measured at it).
struct ViewCamera {
  float eye[3] = {0, 0, 0};
  float view_proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  float fov_y = 0.8f; ///< radians
  float width = 800;  ///< pixels
  float height = 457; ///< pixels
  float near_distance = 0.01f;
};

/// Selective, incremental decoder of a .pomar file. Levels are numbered as everywhere
/// else (0 = base mesh, info().levels.size() = full resolution); clusters can be refined
/// from base_clustered_level() to finest_level(). A pure progressive file has no
/// clusters: it decodes to one uniform level (want_level).
class SelectiveDecoder {
public:
  /// Reads the header and global part and decodes the base clustered mesh. Throws
  /// pomar::Error on a damaged global part, or right after the header if that mesh would
  /// need more memory than `options.memory_limit` (see SelectiveOptions).
  explicit SelectiveDecoder(std::unique_ptr<ByteSource> source,
                            const SelectiveOptions &options = {});
  ~SelectiveDecoder();
  SelectiveDecoder(const SelectiveDecoder &) = delete;
  SelectiveDecoder &operator=(const SelectiveDecoder &) = delete;

  const FileInfo &info() const;
  uint32_t cluster_count() const;
  int base_clustered_level() const; ///< levels decoded for the whole mesh
  /// Clusters that must be decoded to one level (CSR: the clusters linked to c are
  /// link[start[c] .. start[c + 1])): in a file with texture seams, the clusters rooted at
  /// copies of one seam vertex, whose twins split in the same level. Empty lists otherwise.
  void cluster_links(std::vector<uint32_t> &start, std::vector<uint32_t> &link) const;
  int finest_level() const;

  // ----- requests: raise the wanted level of clusters (never lowers it) -----
  void want_cluster(uint32_t cluster, int level);
  void want_all(int level);
  /// Clusters with a vertex of the current mesh inside the sphere / box.
  void want_sphere(const float center[3], float radius, int level);
  void want_box(const float lo[3], const float hi[3], int level);
  /// Clusters of these vertices / faces of the current mesh (what MeshLab selects).
  void want_vertices(const std::vector<uint32_t> &vertices, int level);
  void want_faces(const std::vector<uint32_t> &faces, int level);
  /// Forget every request (the next update() coarsens back to the base clustered mesh).
  void clear_wanted();
  /// Set the wanted levels exactly (one per cluster); lower values coarsen.
  void set_wanted(const std::vector<int> &levels);
  /// View-dependent request: set the wanted levels (as set_wanted) to view_levels(camera,
  /// pixel_error); update() then decodes them. Call again after update() for a new camera
  /// (or the same one: the boxes are then those of the decoded levels).
  void want_view(const ViewCamera &camera, float pixel_error);
  /// The level per cluster a view needs, without requesting it: a cluster outside the view
  /// frustum gets the base clustered level; any other the coarsest level whose error,
  /// projected at the distance from the eye to the cluster, is at most `pixel_error`
  /// pixels. The error is the stored bound (cluster_error) when the file has one, otherwise
  /// the longest edge of the cluster's faces at its current level, scaled to the other
  /// levels by sqrt(faces at the current level / faces at that level) from the level table
  /// (0 at the finest level). The cluster is the box of the current mesh's faces that touch
  /// it, grown by its error at its current level.
  std::vector<int> view_levels(const ViewCamera &camera, float pixel_error) const;
  /// The file stores a geometric error per cluster and level (section CERR).
  bool has_cluster_errors() const;
  /// Its bound for cluster c decoded to `level` (in model units: the deviation of the
  /// cluster's full-resolution vertices from the level's surface, docs/format.md); 0 at the
  /// finest level; -1 if the file stores none.
  double cluster_error(uint32_t cluster, int level) const;
  /// Where cluster c's block lies in the file (from the cluster index and, in a file with
  /// a BLKO section, the block order).
  uint64_t block_offset(uint32_t cluster) const;
  uint32_t block_size(uint32_t cluster) const;
  const std::vector<int> &wanted() const;

  /// Complete the level map (at most one level between neighbouring clusters, section 6)
  /// and bring the mesh to it: decode what is missing on top of the current state, or
  /// re-decode from the base clustered mesh when some cluster must get coarser. Throws
  /// (Kind::MemoryLimit) before decoding anything if the map would need more memory than
  /// SelectiveOptions::memory_limit.
  void update(const Progress &progress = {});

  /// The level map after update(): the level of every cluster.
  const std::vector<int> &levels() const;

  /// Blocks skipped because they failed their checks or were missing (skip_damaged only;
  /// otherwise update() throws). A damaged cluster stays at base_clustered_level() and
  /// limits its neighbours to one level more per step of distance, as the level map rule
  /// demands; the mesh stays valid and every other cluster is decoded as wanted.
  const std::vector<DamagedBlock> &damaged() const;

  // ----- the current mesh -----
  /// Positions, triangles and the attributes of exactly these vertices (the same values a
  /// full decode gives them).
  /// The decoded mesh as coded: a file that carries a lossless record (format version 4)
  /// codes its input cut into a manifold, oriented mesh, and every region shows that cut
  /// mesh (non-manifold vertices and edges as separate copies, flipped faces as coded,
  /// duplicates, faces repeating a vertex and unreferenced vertices absent).
  Mesh mesh() const;
  /// mesh() with the lossless record undone once every cluster is at finest_level() and no
  /// block was skipped: then exactly the encoded input (as pomar::decode gives it);
  /// otherwise the same as mesh(). `source` (optional) receives for each of its vertices
  /// the vertex of mesh() it comes from (UINT32_MAX for a vertex no coded face uses), e.g.
  /// to carry vertex_cluster() and vertex_level() over.
  Mesh exact_mesh(std::vector<uint32_t> *source = nullptr) const;
  /// Every cluster at finest_level() and no block skipped: exact_mesh() is then the
  /// encoded input.
  bool complete() const;
  /// mesh(), handing the decoder's arrays over instead of copying them (a one-shot decode
  /// then needs no memory for a second copy of the mesh). The decoder goes back to the base
  /// clustered mesh (progressive files: the base mesh); the requests stay, so update()
  /// decodes them again.
  Mesh take_mesh();
  /// Per vertex of mesh(): its cluster and the level that created it.
  std::vector<uint32_t> vertex_cluster() const;
  std::vector<uint32_t> vertex_level() const;
  /// Where the cluster levels decoded on top of the base clustered mesh were numbered, in
  /// the order they were applied (level by level, clusters in id order inside a level):
  /// cluster `cluster`'s data of `level` created the vertices first_vertex ..
  /// first_vertex + vertices - 1 and the faces first_face .. first_face + faces - 1 of
  /// mesh(), in the order a full decode creates them (a full decode numbers them from the
  /// counts of the clusters before it in that level instead). Kept with
  /// SelectiveOptions::record_numbering only; empty for progressive files, and again once
  /// the decoder goes back to the base clustered mesh.
  struct NumberedLevel {
    uint32_t cluster, level, first_vertex, vertices, first_face, faces;
  };
  const std::vector<NumberedLevel> &numbered_levels() const;

  // ----- statistics -----
  uint64_t bytes_read() const;       ///< everything read from the source so far
  uint32_t blocks_read() const;      ///< cluster blocks read so far
  uint32_t clusters_decoded() const; ///< clusters above the base clustered level
  /// Passes over a level map by update() so far: one per update() (clustered files), plus
  /// one each time blocks that fail while they are decoded leave a cluster finer than the
  /// damage allows, so that the map is decoded again from the base clustered mesh (every
  /// failure of a pass is met before it decodes again; a block missing from a truncated file
  /// or failing its check is found before anything is decoded and costs no round).
  uint32_t decode_rounds() const;

private:
  struct State;
  std::unique_ptr<State> s_;
};

/// Complete a level map (paper section 6): M(C) = max(wanted(C), max over C' of
/// wanted(C') - d(C, C')), d = edge distance in the cluster graph; levels below `floor`
/// are raised to it. `adjacency` is CSR: neighbours of c are adj[start[c]..start[c+1]).
std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor);
/// The same with cluster links (SelectiveDecoder::cluster_links, CSR as `adj`): linked
/// clusters get one level, the highest any of them needs.
std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor,
                                    const std::vector<uint32_t> &link_start,
                                    const std::vector<uint32_t> &link);

} // namespace pomar
