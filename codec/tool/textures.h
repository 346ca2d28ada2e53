// Texture image files a .pomar file embeds (encode --embed-textures) and a decode writes
// beside its output.
#pragma once

#include <cstddef>
#include <string>

#include "pomar/pomar.h"

namespace pomar::tool {

/// --embed-textures: each texture file's bytes, read beside the input mesh `in`.
void embed_textures(const std::string &in, Mesh &mesh);

/// The decoded mesh's embedded images, written beside `out` under their texture file
/// names; an existing file is never replaced (the same bytes: nothing to do; other bytes:
/// a warning). Returns how many images were written.
size_t write_embedded_textures(const std::string &out, const Mesh &mesh, bool quiet);

} // namespace pomar::tool
