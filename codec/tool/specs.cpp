#include "specs.h"

#include <algorithm>
#include <stdexcept>

#include "pomar/pomar.h"

namespace pomar::tool {

std::vector<double> parse_spec(const std::string &spec, size_t count, int finest, int &level,
                               const char *what) {
  std::string body = spec;
  level = finest;
  const size_t colon = spec.find(':');
  if (colon != std::string::npos) {
    body = spec.substr(0, colon);
    try {
      size_t used = 0;
      level = std::stoi(spec.substr(colon + 1), &used);
      if (used != spec.size() - colon - 1)
        throw std::invalid_argument("level");
    } catch (const std::exception &) {
      throw pomar::Error(pomar::Error::Kind::Usage,
                         std::string("bad ") + what + " '" + spec +
                             "': the level after ':' must be an integer");
    }
  }
  std::vector<double> v;
  size_t pos = 0;
  while (pos <= body.size()) {
    const size_t comma = body.find(',', pos);
    const std::string item =
        body.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size())
        throw std::invalid_argument("number");
    } catch (const std::exception &) {
      throw pomar::Error(pomar::Error::Kind::Usage, std::string("bad ") + what + " '" + spec +
                                                        "': '" + item + "' is not a number");
    }
    if (comma == std::string::npos)
      break;
    pos = comma + 1;
  }
  if (v.size() != count)
    throw pomar::Error(pomar::Error::Kind::Usage, std::string("bad ") + what + " '" + spec +
                                                      "': expected " + std::to_string(count) +
                                                      " numbers");
  return v;
}

pomar::AttributeMask parse_drop(const std::string &list) {
  pomar::AttributeMask keep;
  size_t start = 0;
  while (start <= list.size() && !list.empty()) {
    const size_t comma = std::min(list.find(',', start), list.size());
    const std::string w = list.substr(start, comma - start);
    if (w == "colour" || w == "colours" || w == "color" || w == "colors")
      keep.colour = false;
    else if (w == "normal" || w == "normals")
      keep.normals = false;
    else if (w == "scalar" || w == "scalars" || w == "quality")
      keep.scalars = false;
    else if (w == "texcoord" || w == "texcoords" || w == "uv" || w == "uvs")
      keep.texcoords = false;
    else if (w == "all")
      keep = pomar::AttributeMask::none();
    else
      throw pomar::Error(pomar::Error::Kind::Usage,
                         "bad --drop '" + list + "': '" + w +
                             "' is not one of colour, normals, scalars, texcoords, all");
    start = comma + 1;
  }
  return keep;
}

} // namespace pomar::tool
