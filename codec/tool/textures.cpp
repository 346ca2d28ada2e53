#include "textures.h"

#include <cstdio>
#include <sys/stat.h>

#include "output_paths.h"
#include "pomar/mesh_io.h"

namespace pomar::tool {

void embed_textures(const std::string &in, pomar::Mesh &mesh) {
  mesh.texture_images.assign(mesh.texture_files.size(), {});
  for (size_t t = 0; t < mesh.texture_files.size(); ++t) {
    const std::string &name = mesh.texture_files[t];
    const std::string file = texture_path(in, name);
    const std::string path = file.size() && file[0] == '/' ? file : folder_of(in) + file;
    try {
      mesh.texture_images[t] = pomar::read_file(path);
    } catch (const pomar::Error &e) {
      throw pomar::Error(pomar::Error::Kind::Io, "--embed-textures: texture file '" + name +
                                                     "' of " + in + " cannot be read: " + e.what());
    }
  }
}

size_t write_embedded_textures(const std::string &out, const pomar::Mesh &mesh, bool quiet) {
  size_t written = 0;
  for (size_t t = 0; t < mesh.texture_images.size() && t < mesh.texture_files.size(); ++t) {
    const std::vector<uint8_t> &image = mesh.texture_images[t];
    const std::string name = texture_path(out, mesh.texture_files[t]);
    if (image.empty())
      continue;
    if (!safe_texture_name(name)) {
      std::fprintf(stderr,
                   "pomar: warning: embedded texture %zu not written: its name is not a "
                   "relative path inside the output's folder\n",
                   t);
      continue;
    }
    const std::string path = folder_of(out) + name;
    if (std::FILE *f = std::fopen(path.c_str(), "rb")) {
      std::fclose(f);
      if (pomar::read_file(path) != image && !quiet)
        std::fprintf(stderr,
                     "pomar: warning: %s exists and differs from the embedded texture '%s': "
                     "kept as it is\n",
                     path.c_str(), name.c_str());
      continue;
    }
    const size_t slash = name.rfind('/');
    if (slash != std::string::npos) // its folders inside the output's
      for (size_t at = name.find('/'); at != std::string::npos && at <= slash;
           at = name.find('/', at + 1))
        ::mkdir((folder_of(out) + name.substr(0, at)).c_str(), 0777);
    pomar::write_file_atomic(path, image.data(), image.size());
    ++written;
  }
  return written;
}

} // namespace pomar::tool
