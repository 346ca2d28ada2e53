// PLY header: the "ply" magic, format line, elements and properties (the types plylib
// accepts), TextureFile comments; lines vcglib's parser would mishandle are refused.
#include "io/ply_internal.h"

#include <algorithm>
#include <climits>

namespace pomar::io {

size_t type_size(PlyType t) {
  switch (t) {
  case PlyType::I8:
  case PlyType::U8:
    return 1;
  case PlyType::I16:
  case PlyType::U16:
    return 2;
  case PlyType::I32:
  case PlyType::U32:
  case PlyType::F32:
    return 4;
  case PlyType::F64:
    return 8;
  }
  return 0;
}

namespace {

/// The type names plylib accepts (classic and sized spellings).
bool parse_ply_type(const std::string &s, PlyType &t) {
  static const struct {
    const char *a, *b;
    PlyType t;
  } names[] = {{"char", "int8", PlyType::I8},      {"uchar", "uint8", PlyType::U8},
               {"short", "int16", PlyType::I16},   {"ushort", "uint16", PlyType::U16},
               {"int", "int32", PlyType::I32},     {"uint", "uint32", PlyType::U32},
               {"float", "float32", PlyType::F32}, {"double", "float64", PlyType::F64}};
  for (const auto &n : names)
    if (s == n.a || s == n.b) {
      t = n.t;
      return true;
    }
  return false;
}

std::string base_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

/// vcglib expands "comment TextureFile <name>" into a 255-byte stack buffer, substituting
/// the file's base name for each "<this>"; refuse comments that could overflow it.
void check_texture_comment(const std::string &line, const std::string &path) {
  if (line.find("TextureFile") == std::string::npos)
    return;
  const size_t expansions = static_cast<size_t>(std::count(line.begin(), line.end(), '<'));
  const size_t base = base_name(path).size();
  if (base >= 250 || line.size() + expansions * base >= 250)
    fail(path, "PLY TextureFile comment too long for vcglib");
}

/// Handles one "element" or "property" header line.
void add_ply_declaration(PlyHeader &h, const std::vector<std::string> &tok,
                         const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  if (tok[0] == "element") {
    uint64_t count = 0;
    if (tok.size() < 3 || !parse_count(tok[2], INT_MAX, count))
      bad("bad element line '" + tok[0] + " " + (tok.size() > 1 ? tok[1] : "") + " ...'");
    h.elements.push_back({tok[1], count, {}});
    return;
  }
  if (h.elements.empty())
    bad("property before the first element");
  PlyProperty p;
  const bool list = tok.size() > 1 && tok[1] == "list";
  if (list ? tok.size() < 5 : tok.size() < 3)
    bad("incomplete property line");
  p.is_list = list;
  if (list && !parse_ply_type(tok[2], p.count_type))
    bad("unknown type '" + tok[2] + "'");
  if (!parse_ply_type(tok[list ? 3 : 1], p.type))
    bad("unknown type '" + tok[list ? 3 : 1] + "'");
  p.name = tok[list ? 4 : 2];
  h.elements.back().props.push_back(p);
}

} // namespace

PlyHeader read_ply_header(FileReader &in, const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  std::string line;
  if (!in.line(line) || line.compare(0, 3, "ply") != 0)
    fail(path, "not a PLY file (no 'ply' magic)");
  PlyHeader h;
  bool have_format = false;
  for (;;) {
    if (!in.line(line))
      bad("no end_header");
    if (line.size() > 500) // plylib reads header lines in 511-byte pieces
      bad("line longer than 500 characters");
    if (line.find('\0') != std::string::npos) // plylib's strtok would stop there
      bad("NUL byte");
    const std::vector<std::string> tok = split_ws(line);
    if (tok.empty())
      bad("empty line");
    if (tok[0] == "comment" || tok[0] == "obj_info") {
      check_texture_comment(line, path);
      const size_t at = line.find("TextureFile");
      if (tok[0] == "comment" && tok.size() >= 3 && tok[1] == "TextureFile") {
        std::string name = line.substr(line.find_first_not_of(" \t", at + 11));
        while (!name.empty() && (name.back() == '\r' || name.back() == ' '))
          name.pop_back();
        h.texture_files.push_back(name);
      }
    } else if (tok[0] == "end_header") {
      break;
    } else if (tok[0] == "format") {
      if (have_format || !h.elements.empty() || tok.size() < 3)
        bad("misplaced or incomplete format line");
      if (tok[1] == "ascii")
        h.encoding = PlyHeader::Ascii;
      else if (tok[1] == "binary_little_endian")
        h.encoding = PlyHeader::BinaryLittle;
      else if (tok[1] == "binary_big_endian")
        h.encoding = PlyHeader::BinaryBig;
      else
        bad("unknown format '" + tok[1] + "'");
      have_format = true;
    } else if (tok[0] == "element" || tok[0] == "property") {
      if (!have_format)
        bad("format line missing before '" + tok[0] + "'");
      add_ply_declaration(h, tok, path);
    } else {
      bad("unexpected keyword '" + tok[0] + "'");
    }
  }
  if (!have_format)
    bad("no format line");
  return h;
}

uint64_t element_count(const PlyHeader &h, const char *name) {
  for (const PlyElement &e : h.elements)
    if (e.name == name)
      return e.count;
  return 0;
}

} // namespace pomar::io
