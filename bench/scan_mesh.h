// A scan-like procedural mesh of any size, written to a binary PLY as a stream: its
// memory does not grow with the vertex count (a few rows of one component at a time), so
// tests and benchmarks can make inputs of 10M-100M vertices without holding them.
//
// The mesh: `components` closed latitude-longitude spheres of decreasing size side by side
// (the first holds about half of the vertices, with 5), each displaced radially by four octaves of
// smooth bumps (the "detail") and by per-vertex noise of about a thousandth of its radius
// (the scanner's noise), with a few round holes (spherical caps of vertices left out, and the
// faces that used them): 3 in the first component, 1 in each other but the last, which stays
// closed. Every vertex is used by a face. Deterministic for a given (vertices, seed,
// components).
#pragma once

#include <cstdint>
#include <string>

namespace pomar::bench {

struct ScanMeshOptions {
  uint64_t vertices = 1000000; ///< approximate count (the holes take a little off)
  uint32_t seed = 1;
  int components = 5; ///< 1..16
};

struct ScanMeshCounts {
  uint64_t vertices = 0, faces = 0;
};

/// What write_scan_ply would write, without writing it (one pass over the holes only).
ScanMeshCounts count_scan_mesh(const ScanMeshOptions &options);

/// Writes the mesh as binary little-endian PLY (float x, y, z; uchar-counted uint index
/// lists). Returns false (and `error` says why) when the file cannot be written or the mesh
/// would have more than 2^32 - 1 vertices.
bool write_scan_ply(const ScanMeshOptions &options, const std::string &path, ScanMeshCounts &counts,
                    std::string &error);

} // namespace pomar::bench
