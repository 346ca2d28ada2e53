// Paths the tool derives from its arguments: extensions, folders, texture files beside a
// mesh, and the refusals of an output path (the input itself; a .pomar under a mesh
// extension).
#pragma once

#include <string>

namespace pomar::tool {

/// The extension of `path` in lower case (".ply"), "" if it has none.
std::string lower_extension(const std::string &path);

/// The folder of `path` ("" for the current one), with a trailing '/'.
std::string folder_of(const std::string &path);

/// A texture file name as a path beside `mesh_path`: MeshLab's "<this>" stands for the mesh
/// file's name without its extension.
std::string texture_path(const std::string &mesh_path, const std::string &name);

/// A texture file name a decode may write beside its output: relative, no "..", no control
/// characters (the names come from the file).
bool safe_texture_name(const std::string &name);

/// Refuse (pomar::Error, Usage) an output that is the input (the same file, also through
/// links: it would be overwritten) and, unless `force`, a .pomar file written under a mesh
/// file's extension.
void check_output(const std::string &in, const std::string &out, bool pomar_output, bool force);

/// What follows the list of what a mesh file cannot hold: where it would be kept.
const char *not_written_hint(const std::string &path);

} // namespace pomar::tool
