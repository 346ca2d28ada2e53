// pomar::decode (a global level target decodes the global levels here; a clustered target
// goes through the SelectiveDecoder), pomar::inspect, pomar::check_blocks,
// pomar::describe_damage.
#include <algorithm>
#include <memory>
#include <string>

#include "attributes/attribute_section.h"
#include "attributes/material_section.h"
#include "attributes/texture_images.h"
#include "decode/damage.h"
#include "decode/decoder_codec.h"
#include "decode/global_levels.h"
#include "entropy/models.h"
#include "format/block_checks.h"
#include "format/block_order.h"
#include "format/cluster_errors.h"
#include "format/file_format.h"
#include "lossless/lossless_stage.h"
#include "parallel/thread_pool.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"

namespace pomar {

FileInfo inspect(const uint8_t *data, size_t size) {
  const FileLayout layout = read_layout(data, size);
  read_base_mesh(data, layout, false); // checks the base block too (nothing kept)
  FileInfo info = file_info(layout, size);
  lossless_info(data, layout, info);
  if (layout.header.clustered()) {
    check_block(data + layout.tables_offset, layout.header.tables_bytes,
                layout.header.tables_checksum, "static model tables");
    ClusterIndex index = read_cluster_index(data + layout.index_offset, layout);
    load_block_checks(data, layout, index); // (read at open by every decode)
    info.cluster_block_bytes = index.size;
  }
  const auto table = load_attribute_table(data, layout, false); // (no codes kept)
  const size_t textures = table ? table->texture_files.size() : 0;
  // The materials, as every decode reads them (a damaged MATL section fails here too).
  load_material_table(data, layout, textures);
  if (table) {
    describe_attributes(*table, info);
    info.embedded_texture_bytes = texture_image_sizes(data, layout, textures);
  }
  return info;
}

std::string printable(const std::string &text) {
  std::string out;
  out.reserve(text.size());
  const auto escape = [&](unsigned char c) {
    static const char hex[] = "0123456789abcdef";
    out += "\\x";
    out += hex[c >> 4];
    out += hex[c & 15];
  };
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      if (c < 0x20 || c == 0x7F)
        escape(c);
      else
        out += char(c);
      ++i;
      continue;
    }
    // A UTF-8 sequence: its length from the lead byte, continuation bytes 10xxxxxx, no
    // overlong two-byte form, no surrogates, at most U+10FFFF.
    const size_t n = c >= 0xC2 && c <= 0xDF   ? 2
                     : c >= 0xE0 && c <= 0xEF ? 3
                     : c >= 0xF0 && c <= 0xF4 ? 4
                                              : 0;
    bool ok = n != 0 && i + n <= text.size();
    for (size_t k = 1; ok && k < n; ++k)
      ok = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (ok && n >= 3) {
      const unsigned char d = static_cast<unsigned char>(text[i + 1]);
      ok = !(c == 0xE0 && d < 0xA0) && !(c == 0xED && d >= 0xA0) && !(c == 0xF0 && d < 0x90) &&
           !(c == 0xF4 && d >= 0x90);
    }
    if (!ok) {
      escape(c);
      ++i;
      continue;
    }
    out.append(text, i, n);
    i += n;
  }
  return out;
}

std::string describe_damage(const std::vector<DamagedBlock> &blocks, size_t first,
                            size_t max_lines) {
  std::string out;
  const size_t end = std::min(blocks.size(), first + max_lines);
  for (size_t i = first; i < end; ++i) {
    const DamagedBlock &b = blocks[i];
    out += (i == first ? "  " : "\n  ") + b.block;
    if (b.level_kept >= 0)
      out += " (kept at level " + std::to_string(b.level_kept) + ")";
    out += ": " + b.problem;
  }
  if (end < blocks.size())
    out += "\n  ... and " + std::to_string(blocks.size() - end) + " more";
  return out;
}

std::vector<DamagedBlock> check_blocks(const uint8_t *data, size_t size, uint64_t memory_limit) {
  const FileLayout layout = read_layout(data, size, size, true);
  const FileHeader &h = layout.header;
  read_base_mesh(data, layout, false);
  // The sections lie in the global part, which every decode needs: each is read as a decode
  // reads it, so that a file said to be whole decodes; a failure throws, as for the base
  // mesh. The base mesh's attribute codes are checked as they are read, without being kept;
  // only wedge texture coordinates, predicted from the base mesh's neighbours, need the base
  // mesh and its codes (the memory a decode of the base mesh needs, checked first).
  if (const auto attributes = load_attribute_table(data, layout, false)) {
    const size_t textures = attributes->texture_files.size();
    load_material_table(data, layout, textures);
    texture_image_sizes(data, layout, textures);
    if (attributes->wedge_pending) {
      FileInfo info = file_info(layout, size);
      describe_attributes(*attributes, info);
      check_decode_memory(info, 0, memory_limit); // (the base mesh: level 0)
      const auto kept = load_attribute_table(data, layout);
      LevelMesh lm = base_level_mesh(data, layout);
      init_attributes(*kept, lm);
    }
  }
  {
    FileInfo counts;
    lossless_info(data, layout, counts);
  }
  std::vector<DamagedBlock> damaged;
  const size_t global = h.clustered() ? h.global_levels : h.levels.size();
  for (size_t i = 0; i < global; ++i) {
    try {
      check_level(data, layout, i);
    } catch (const Error &e) {
      damaged.push_back(damaged_level(i + 1, e.what()));
    }
  }
  if (!h.clustered())
    return damaged;
  check_block(data + layout.tables_offset, h.tables_bytes, h.tables_checksum,
              "static model tables");
  ClusterIndex index = read_cluster_index(data + layout.index_offset, layout);
  load_block_checks(data, layout, index);
  if (has_block_order(data, layout)) { // the blocks lie in the Morton order of their roots
    LevelMesh lm = base_level_mesh(data, layout);
    Models models;
    if (const auto attributes = load_attribute_table(data, layout)) {
      init_attributes(*attributes, lm, AttributeMask::none()); // read past, not kept
      models.attr = attribute_models(*attributes);
    }
    if (!damaged.empty()) // a damaged global level: the roots, so the blocks, are unknown
      return damaged;
    decode_global_levels(data, layout, 0, h.global_levels, lm, models, {});
    place_blocks(index, morton_block_order(lm.q, h.clusters, h.grid.bits), layout);
  }
  load_cluster_errors(data, layout); // (the global part: a failure throws)
  for (uint32_t c = 0; c < h.clusters; ++c) {
    const char *problem = nullptr;
    if (index.offset[c] + index.size[c] > size)
      problem = "missing: the file ends before this block (truncated file)";
    else if (!passes_block_check(data + index.offset[c], index.size[c], index.check[c],
                                 index.check_mask))
      problem = "checksum mismatch";
    if (problem)
      damaged.push_back(damaged_cluster(c,
                                        std::string("damaged .pomar file: block of cluster ") +
                                            std::to_string(c) + ": " + problem,
                                        static_cast<int>(h.global_levels)));
  }
  // Version 3: the cluster data as a whole (catches what the 8-bit checks let through).
  const uint64_t end = layout.clusters_offset + h.cluster_bytes;
  if (damaged.empty() && h.has_cluster_checksum && end <= size &&
      checksum(data + layout.clusters_offset, h.cluster_bytes) != h.cluster_checksum)
    damaged.push_back(unlocated_damage(kUnlocatedDamage));
  return damaged;
}

Mesh decode(const uint8_t *data, size_t size, int level, const Progress &progress,
            uint64_t memory_limit) {
  DecodeOptions options;
  options.level = level;
  options.progress = progress;
  options.memory_limit = memory_limit;
  return decode(data, size, options);
}

namespace {

/// What a skip_damaged decode says when the lossless record is damaged.
const char *const kCutMeshKept =
    " (the mesh is the coded one: cut into a manifold, oriented mesh, without its duplicate and "
    "degenerate faces and unreferenced vertices)";

/// Undo the lossless record's cut on the full decoded mesh; with skip_damaged, a damaged
/// record is reported and the coded mesh kept (undo_cut changes nothing when it throws).
void undo_cut_or_report(const uint8_t *data, const FileLayout &layout, const DecodeOptions &options,
                        DecodeReport &r, Mesh &mesh) {
  try {
    undo_cut(data, layout, mesh);
  } catch (const Error &e) {
    if (!options.skip_damaged)
      throw;
    r.damaged.push_back({"lossless record", std::string(e.what()) + kCutMeshKept, -1});
  }
}

} // namespace

Mesh decode(const uint8_t *data, size_t size, const DecodeOptions &options, DecodeReport *report) {
  DecodeReport scratch_report;
  DecodeReport &r = report ? *report : scratch_report;
  r = DecodeReport();
  const FileLayout layout = read_layout(data, size, size, options.skip_damaged);
  require_known_sections(layout);
  const FileHeader &h = layout.header;
  const size_t levels = h.levels.size();
  if (options.level != -1) // -1: full resolution
    check_level_exists(options.level, static_cast<int>(levels));
  // The ATTR section's descriptors first (its base mesh codes checked, not kept): the
  // attributes count in the check, which comes before the codes are stored.
  std::unique_ptr<AttributeTable> attributes = load_attribute_table(data, layout, false);
  const std::unique_ptr<MaterialTable> materials =
      load_material_table(data, layout, attributes ? attributes->texture_files.size() : 0);
  FileInfo info = file_info(layout, size);
  if (attributes)
    describe_attributes(*attributes, info);
  const unsigned threads = decode_threads(options.threads);
  check_decode_memory(info, options.level, options.memory_limit, options.attributes, threads);
  if (attributes)
    attributes = load_attribute_table(data, layout);
  const size_t target = options.level < 0 ? levels : static_cast<size_t>(options.level);
  const size_t global = h.clustered() ? h.global_levels : levels;
  // Clustered levels go through the selective decoder, unless a global level they build
  // on is damaged (then the decoding stops there, below).
  bool global_intact = true;
  if (target > global && options.skip_damaged)
    for (size_t i = 0; i < global && global_intact; ++i) {
      try {
        check_level(data, layout, i);
      } catch (const Error &) {
        global_intact = false;
      }
    }
  if (target > global && global_intact) { // clustered levels: every cluster at `target`
    // The stored errors, which this decode does not use and a SelectiveDecoder reads only
    // for a view: the whole file is at hand, so a damaged section is found here as before.
    std::string errors_damage;
    try {
      load_cluster_errors(data, layout);
    } catch (const Error &e) {
      if (!options.skip_damaged)
        throw;
      errors_damage = e.what();
    }
    // Checked above for the whole target level; the constructor's check is smaller.
    SelectiveOptions so;
    so.skip_damaged = options.skip_damaged;
    so.attributes = options.attributes;
    so.memory_limit = kNoMemoryLimit;
    so.threads = threads;
    so.min_parallel_vertices = options.min_parallel_vertices;
    SelectiveDecoder d(std::make_unique<MemorySource>(data, size), so);
    d.want_all(static_cast<int>(target));
    d.update(options.progress);
    r.damaged = d.damaged();
    if (!errors_damage.empty())
      r.damaged.push_back({"section CERR", errors_damage + " (not needed by the mesh)", -1});
    r.decode_rounds = d.decode_rounds();
    for (int l : d.levels()) {
      r.level = std::max(r.level, l);
      r.clusters_below_request += l < static_cast<int>(target);
    }
    const bool complete = d.complete();
    Mesh mesh = d.take_mesh(); // (no second copy of the mesh)
    if (complete)
      undo_cut_or_report(data, layout, options, r, mesh); // the full mesh: as it was input
    attach_texture_images(data, layout, attributes.get(), options.attributes, mesh);
    return mesh;
  }
  LevelMesh lm = base_level_mesh(data, layout);
  Models models;
  if (attributes) {
    init_attributes(*attributes, lm, options.attributes);
    models.attr = attribute_models(*attributes);
  }
  const size_t reach = std::min(target, global);
  if (reach > 0)
    lm.reserve(h.levels[reach - 1].vertices, h.levels[reach - 1].faces, size);
  r.level = static_cast<int>(decode_global_levels(data, layout, 0, std::min(target, global), lm,
                                                  models, options.progress,
                                                  options.skip_damaged ? &r.damaged : nullptr));
  // Hands over the triangles (no copy); the vertex count and the attribute codes stay.
  Mesh mesh = to_mesh(std::move(lm), h.grid);
  if (attributes)
    attach_attributes(*attributes, lm, options.attributes, mesh);
  if (materials)
    attach_materials(*materials, options.attributes, mesh);
  attach_texture_images(data, layout, attributes.get(), options.attributes, mesh);
  if (r.level == static_cast<int>(levels))
    undo_cut_or_report(data, layout, options, r, mesh); // the full mesh: as it was input
  return mesh;
}

} // namespace pomar
