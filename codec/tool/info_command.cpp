// pomar info: a .pomar file's counts, levels, sections and sizes (text or --json), or
// every block's checksum (--check, exit 4 when one fails).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>

#include "commands.h"
#include "console.h"
#include "exit_codes.h"
#include "pomar/limits.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"

namespace pomar::tool {

namespace {

bool has_section(const pomar::FileInfo &i, const char *name) {
  return std::any_of(i.sections.begin(), i.sections.end(),
                     [&](const pomar::FileInfo::Section &s) { return s.name == name; });
}

/// What a section the tool knows holds, for the text listing ("" otherwise).
const char *section_meaning(const std::string &name) {
  if (name == "CERR")
    return ": stored errors, a bound per cluster and level for view-dependent decoding";
  if (name == "BLKO")
    return ": cluster blocks in spatial (Morton) order";
  return "";
}

nlohmann::json info_json(const pomar::FileInfo &i) {
  nlohmann::json j;
  j["version"] = i.version;
  j["vertices"] = i.vertices;
  j["faces"] = i.faces;
  j["bits"] = i.bits;
  j["bbox_min"] = {i.bbox_min[0], i.bbox_min[1], i.bbox_min[2]};
  j["grid_max"] = {i.bbox_max[0], i.bbox_max[1], i.bbox_max[2]};
  j["base_vertices"] = i.base_vertices;
  j["base_faces"] = i.base_faces;
  nlohmann::json levels = nlohmann::json::array();
  levels.push_back({{"level", 0},
                    {"vertices", i.base_vertices},
                    {"faces", i.base_faces},
                    {"bytes", i.base_bytes}});
  for (size_t l = 0; l < i.levels.size(); ++l)
    levels.push_back({{"level", l + 1},
                      {"vertices", i.levels[l].vertices},
                      {"faces", i.levels[l].faces},
                      {"connectivity_bytes", i.levels[l].connectivity_bytes},
                      {"geometry_bytes", i.levels[l].geometry_bytes}});
  j["levels"] = levels;
  j["level_count"] = i.levels.size();
  j["connectivity_bits"] = 8 * i.connectivity_bytes;
  j["geometry_bits"] = 8 * i.geometry_bytes;
  j["clusters"] = i.clusters;
  j["global_levels"] = i.global_levels;
  j["global_bytes"] = i.global_bytes;
  j["tables_bytes"] = i.tables_bytes;
  j["index_bytes"] = i.index_bytes;
  j["cluster_bytes"] = i.cluster_bytes;
  j["lossless_bytes"] = i.lossless_bytes;
  j["lossless_bits_per_vertex"] = bpv(i.lossless_bytes, i.vertices);
  j["input_vertices"] = i.input_vertices;
  j["input_faces"] = i.input_faces;
  j["cluster_block_bytes"] = i.cluster_block_bytes;
  nlohmann::json sections = nlohmann::json::array();
  for (const pomar::FileInfo::Section &sec : i.sections)
    sections.push_back({{"name", sec.name},
                        {"bytes", sec.bytes},
                        {"bpv", bpv(sec.bytes, i.vertices)},
                        {"required", sec.required}});
  j["sections"] = sections;
  if (i.clustered()) {
    j["stored_errors"] = has_section(i, "CERR");
    j["block_order"] = has_section(i, "BLKO") ? "spatial" : "id";
  }
  j["header_bytes"] = i.header_bytes;
  j["base_bytes"] = i.base_bytes;
  j["total_bytes"] = i.total_bytes;
  j["bpv"] = bpv(i.total_bytes, i.vertices);
  j["connectivity_bpv"] = bpv(i.connectivity_bytes, i.vertices);
  j["geometry_bpv"] = bpv(i.geometry_bytes, i.vertices);
  nlohmann::json attributes = nlohmann::json::array();
  for (const pomar::AttributeInfo &a : i.attributes)
    attributes.push_back({{"kind", pomar::kind_name(a.kind)},
                          {"name", a.name},
                          {"components", a.components},
                          {"bits", a.bits},
                          {"exact", a.bits == 0},
                          {"bound", a.bound},
                          {"bytes", a.bytes},
                          {"bpv", bpv(a.bytes, i.vertices)}});
  j["attributes"] = attributes;
  j["attribute_bytes"] = i.attribute_bytes;
  j["texture_files"] = i.texture_files;
  j["embedded_texture_bytes"] = i.embedded_texture_bytes;
  return j;
}

/// info --check: every block's checksum; exit kExitDamaged if one fails.
int run_check(const std::string &in, const std::string &max_memory) {
  const uint64_t memory_limit = pomar::parse_memory_size(max_memory);
  const std::vector<uint8_t> data = pomar::read_file(in);
  const std::vector<pomar::DamagedBlock> damaged =
      pomar::check_blocks(data.data(), data.size(), memory_limit);
  if (damaged.empty()) {
    std::printf("%s: every block passes its check\n", in.c_str());
    return 0;
  }
  std::printf("%s: %zu damaged block%s (pomar decode --skip-damaged decodes the rest):\n",
              in.c_str(), damaged.size(), damaged.size() == 1 ? "" : "s");
  for (const pomar::DamagedBlock &b : damaged)
    std::printf("  %s: %s\n", b.block.c_str(), b.problem.c_str());
  return kExitDamaged;
}

int print_info(const std::string &in, bool json) {
  const std::vector<uint8_t> data = pomar::read_file(in);
  const pomar::FileInfo i = pomar::inspect(data.data(), data.size());
  if (json) {
    std::printf("%s\n", info_json(i).dump(2).c_str());
    return 0;
  }
  if (i.clustered())
    std::printf("%s: .pomar version %u, random access: %u clusters, levels 1..%u global\n",
                in.c_str(), i.version, i.clusters, i.global_levels);
  else
    std::printf("%s: .pomar version %u, pure progressive (global levels only)\n", in.c_str(),
                i.version);
  std::printf("  vertices %u, faces %u, %d-bit grid from (%g, %g, %g), cell %.6g\n", i.vertices,
              i.faces, i.bits, i.bbox_min[0], i.bbox_min[1], i.bbox_min[2],
              (double(i.bbox_max[0]) - i.bbox_min[0]) / double((1u << i.bits) - 1));
  std::printf("  size %lu bytes = %.2f bits/vertex: connectivity %.2f, geometry %.2f, base mesh "
              "%.2f, header %.2f\n",
              static_cast<unsigned long>(i.total_bytes), bpv(i.total_bytes, i.vertices),
              bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices),
              bpv(i.base_bytes, i.vertices), bpv(i.header_bytes, i.vertices));
  if (!i.attributes.empty() || !i.texture_files.empty()) {
    uint64_t coded = 0;
    for (const pomar::AttributeInfo &a : i.attributes)
      coded += a.bytes;
    std::printf("  attributes about %.2f bits/vertex, coded with the positions in the levels and "
                "cluster blocks (encoder's estimate; ATTR section with the base mesh's: %lu "
                "bytes):\n",
                bpv(coded, i.vertices), static_cast<unsigned long>(i.attribute_bytes));
    print_attributes(i);
  }
  if (i.clustered()) {
    std::vector<uint32_t> sizes = i.cluster_block_bytes;
    std::sort(sizes.begin(), sizes.end());
    std::printf("  global part %lu bytes (header, base mesh, %u global levels, model tables %lu, "
                "cluster index %lu); cluster blocks %lu bytes\n",
                static_cast<unsigned long>(i.global_bytes), i.global_levels,
                static_cast<unsigned long>(i.tables_bytes),
                static_cast<unsigned long>(i.index_bytes),
                static_cast<unsigned long>(i.cluster_bytes));
    if (!sizes.empty())
      std::printf("  %u clusters, block bytes min %u, median %u, max %u (pomar info --json lists "
                  "them all)\n",
                  i.clusters, sizes.front(), sizes[sizes.size() / 2], sizes.back());
    std::printf("  blocks in %s; %s\n",
                has_section(i, "BLKO") ? "spatial (Morton) order" : "cluster id order",
                has_section(i, "CERR")
                    ? "stored errors per cluster and level"
                    : "no stored errors (views estimate them from edge lengths)");
  }
  for (const pomar::FileInfo::Section &sec : i.sections)
    std::printf("  section %s: %lu bytes = %.2f bits/vertex%s%s\n",
                pomar::printable(sec.name).c_str(), static_cast<unsigned long>(sec.bytes),
                bpv(sec.bytes, i.vertices), sec.required ? " (required)" : "",
                section_meaning(sec.name));
  if (i.lossless_bytes)
    std::printf("  lossless record (section LSLS): a full decode gives back the input's %lu "
                "vertices and %lu faces exactly (levels and regions show the coded, cut mesh)\n",
                static_cast<unsigned long>(i.input_vertices),
                static_cast<unsigned long>(i.input_faces));
  std::printf("  level  vertices     faces  conn.bytes  geom.bytes\n");
  std::printf("  %5d %9u %9u  %10lu  (base mesh)\n", 0, i.base_vertices, i.base_faces,
              static_cast<unsigned long>(i.base_bytes));
  for (size_t l = 0; l < i.levels.size(); ++l) {
    if (l < i.global_levels)
      std::printf("  %5zu %9u %9u  %10lu  %10lu\n", l + 1, i.levels[l].vertices, i.levels[l].faces,
                  static_cast<unsigned long>(i.levels[l].connectivity_bytes),
                  static_cast<unsigned long>(i.levels[l].geometry_bytes));
    else
      std::printf("  %5zu %9u %9u  (clustered)\n", l + 1, i.levels[l].vertices, i.levels[l].faces);
  }
  return 0;
}

} // namespace

int run_info(const InfoArgs &a) {
  return a.check ? run_check(a.in, a.max_memory) : print_info(a.in, a.json);
}

} // namespace pomar::tool
