// The tool's four commands: what each takes from the command line (filled in by main.cpp's
// command table) and the function that runs it, returning the exit status (exit_codes.h).
// Errors are thrown as pomar::Error; main() prints them and maps their kind to the status.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pomar/attributes.h"

namespace pomar::tool {

struct EncodeArgs {
  std::string in, out;
  int bits = 12;
  uint32_t clusters = 0;
  double cluster_ratio = 0.01;
  bool progressive = false, quiet = false, repair = false, strict = false, keep_order = false;
  bool embed_textures = false, force = false;
  bool no_stored_errors = false;
  std::string block_order = "spatial";
  std::string max_memory = "auto";
  unsigned threads = 0;
  pomar::AttributeOptions attributes;
  std::string drop;
};

struct DecodeArgs {
  std::string in, out;
  int level = -1;
  std::vector<std::string> clusters, spheres, boxes;
  bool ascii = false, quiet = false, stats = false, skip_damaged = false;
  bool no_attributes = false;
  unsigned threads = 0;
  std::string max_memory = "auto";
  bool selective() const { return !clusters.empty() || !spheres.empty() || !boxes.empty(); }
};

struct InfoArgs {
  std::string in, max_memory = "auto";
  bool json = false, check = false;
};

struct VerifyArgs {
  std::string original, file, decoded, drop;
  bool repair = false;
};

/// encode_command.cpp: a mesh file into a .pomar file.
int run_encode(const EncodeArgs &a);

/// decode_command.cpp: a .pomar file into a mesh file (whole, to a level, or regions).
int run_decode(const DecodeArgs &a);

/// info_command.cpp: a .pomar file described (text or JSON), or its blocks checked.
int run_info(const InfoArgs &a);

/// verify_command.cpp: a .pomar file (or a mesh decoded from it) against the original.
int run_verify(const VerifyArgs &a);

} // namespace pomar::tool
