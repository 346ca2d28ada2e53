#include "output_paths.h"

#include <algorithm>
#include <cctype>
#include <sys/stat.h>

#include "pomar/pomar.h"

namespace pomar::tool {

std::string lower_extension(const std::string &path) {
  const size_t dot = path.rfind('.'), slash = path.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string folder_of(const std::string &path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::string texture_path(const std::string &mesh_path, const std::string &name) {
  std::string base = mesh_path.substr(folder_of(mesh_path).size());
  if (const size_t dot = base.rfind('.'); dot != std::string::npos && dot > 0)
    base.resize(dot);
  std::string out = name;
  for (size_t at = out.find("<this>"); at != std::string::npos; at = out.find("<this>", at))
    out.replace(at, 6, base);
  return out;
}

bool safe_texture_name(const std::string &name) {
  if (name.empty() || name[0] == '/' || name.find('\\') != std::string::npos)
    return false;
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7F)
      return false;
  for (size_t start = 0; start <= name.size();) {
    const size_t end = std::min(name.find('/', start), name.size());
    const std::string part = name.substr(start, end - start);
    if (part == ".." || part.empty())
      return false;
    start = end + 1;
  }
  return true;
}

void check_output(const std::string &in, const std::string &out, bool pomar_output, bool force) {
  struct stat a, b;
  if (::stat(in.c_str(), &a) == 0 && ::stat(out.c_str(), &b) == 0 && a.st_dev == b.st_dev &&
      a.st_ino == b.st_ino)
    throw pomar::Error(pomar::Error::Kind::Usage,
                       "the output " + out + " is the input " + in +
                           ": it would be overwritten; choose another output file");
  if (!pomar_output || force)
    return;
  const std::string ext = lower_extension(out);
  if (ext == ".ply" || ext == ".obj" || ext == ".off" || ext == ".stl")
    throw pomar::Error(pomar::Error::Kind::Usage,
                       "the output " + out +
                           " has a mesh file's extension, but pomar encode "
                           "writes a .pomar file, which mesh readers cannot open: name it " +
                           out.substr(0, out.size() - ext.size()) +
                           ".pomar (or add --force to write it under this name)");
}

const char *not_written_hint(const std::string &path) {
  return lower_extension(path) == ".ply" ? ": not written (.obj keeps them)"
                                         : ": not written (.ply keeps every attribute)";
}

} // namespace pomar::tool
