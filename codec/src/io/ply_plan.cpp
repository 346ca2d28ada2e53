// What of a PLY file's vertex and face elements is kept as attributes (the plans the walk
// reads into).
#include "io/ply_internal.h"

namespace pomar::io {

PlyVertexPlan plan_vertex_attributes(const PlyElement *vertex, std::vector<std::string> &ignored) {
  PlyVertexPlan plan;
  if (!vertex)
    return plan;
  plan.slots.resize(vertex->props.size());
  std::vector<bool> taken(vertex->props.size(), false);
  auto index = [&](const char *name) -> int {
    for (size_t i = 0; i < vertex->props.size(); ++i)
      if (vertex->props[i].name == name && !vertex->props[i].is_list)
        return static_cast<int>(i);
    return -1;
  };
  auto is_float = [&](int i) {
    return vertex->props[i].type == PlyType::F32 || vertex->props[i].type == PlyType::F64;
  };
  auto add = [&](AttributeKind kind, const std::string &name, const std::vector<int> &props) {
    VertexAttribute a;
    a.kind = kind;
    a.name = name;
    a.components = static_cast<uint32_t>(props.size());
    for (size_t k = 0; k < props.size(); ++k) {
      plan.slots[props[k]] = {static_cast<int>(plan.attributes.size()), static_cast<uint32_t>(k)};
      taken[props[k]] = true;
    }
    plan.attributes.push_back(a);
  };
  for (const char *prefix : {"", "diffuse_"}) {
    const std::string p = prefix;
    const int r = index((p + "red").c_str()), g = index((p + "green").c_str()),
              b = index((p + "blue").c_str()), a = index((p + "alpha").c_str());
    if (r < 0 || g < 0 || b < 0 || taken[r] || taken[g] || taken[b])
      continue;
    std::vector<int> props = {r, g, b};
    if (a >= 0)
      props.push_back(a);
    bool bytes = true;
    for (int i : props)
      bytes &= vertex->props[i].type == PlyType::U8;
    if (bytes) {
      add(AttributeKind::Colour, "colour", props);
    } else {
      add_unique(ignored, vertex->props[r].type == PlyType::U16
                              ? "colors (16-bit channels: pomar keeps 8-bit colour)"
                              : "colors (channels not 8-bit: pomar keeps 8-bit colour)");
      for (int i : props)
        taken[i] = true;
    }
  }
  const int nx = index("nx"), ny = index("ny"), nz = index("nz");
  if (nx >= 0 && ny >= 0 && nz >= 0 && is_float(nx) && is_float(ny) && is_float(nz))
    add(AttributeKind::Normal, "normal", {nx, ny, nz});
  for (const auto &uv :
       {std::pair<const char *, const char *>{"texture_u", "texture_v"}, {"u", "v"}, {"s", "t"}}) {
    const int u = index(uv.first), v = index(uv.second);
    if (u >= 0 && v >= 0 && !taken[u] && !taken[v] && is_float(u) && is_float(v)) {
      add(AttributeKind::TexCoord, "texcoord", {u, v});
      break;
    }
  }
  for (size_t i = 0; i < vertex->props.size(); ++i) {
    const PlyProperty &prop = vertex->props[i];
    if (taken[i] || prop.name == "x" || prop.name == "y" || prop.name == "z")
      continue;
    if (prop.name == "flags")
      add_unique(ignored, "flags");
    else if (prop.is_list)
      add_unique(ignored, ("vertex list property '" + prop.name + "'").c_str());
    else if (prop.name.empty() || prop.name.size() > 255)
      add_unique(ignored, "vertex property with an unusable name");
    else
      add(AttributeKind::Scalar, prop.name, {static_cast<int>(i)});
  }
  return plan;
}

PlyFaceData plan_face_data(const PlyHeader &h) {
  PlyFaceData d;
  for (const PlyElement &e : h.elements)
    if (e.name == "face") {
      const PlyProperty *tc = e.find("texcoord"), *tn = e.find("texnumber");
      if (tc && tc->is_list && (tc->type == PlyType::F32 || tc->type == PlyType::F64))
        d.texcoord = tc;
      if (tn && !tn->is_list)
        d.texnumber = tn;
      break;
    }
  return d;
}

} // namespace pomar::io
