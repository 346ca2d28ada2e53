// The tool's value syntaxes: region specs ("X,Y,Z,R[:LEVEL]") and attribute lists
// ("colour,normals").
#pragma once

#include <string>
#include <vector>

#include "pomar/attributes.h"

namespace pomar::tool {

/// "a,b,c[:LEVEL]" -> `count` numbers and the level (default `finest`); `what` names the
/// option in the message. Throws pomar::Error (Usage).
std::vector<double> parse_spec(const std::string &spec, size_t count, int finest, int &level,
                               const char *what);

/// "--drop colour,normals,scalars,texcoords" (also "color", "normal", "scalar", "texcoord",
/// "uv", "all") as a mask of what is kept. Throws pomar::Error (Usage).
AttributeMask parse_drop(const std::string &list);

} // namespace pomar::tool
