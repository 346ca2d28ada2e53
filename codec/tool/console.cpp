#include "console.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

#include "pomar/repair.h"

namespace pomar::tool {

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

pomar::Progress terminal_progress(bool quiet) {
  if (quiet || !isatty(fileno(stderr)))
    return {};
  return [last = -1](double f, const char *stage) mutable {
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last)
      return;
    last = pct;
    std::fprintf(stderr, "\r%-10s %3d%%", stage, pct);
    if (pct >= 100)
      std::fprintf(stderr, "\r%20s\r", "");
    std::fflush(stderr);
  };
}

double repair_and_report(pomar::Mesh &mesh, bool quiet) {
  const auto t0 = Clock::now();
  const pomar::RepairReport r = pomar::make_manifold(mesh);
  const double seconds = since(t0);
  if (!r.changed() && quiet)
    return seconds;
  const std::string summary = r.summary();
  size_t begin = 0;
  while (begin <= summary.size()) {
    const size_t end = std::min(summary.find('\n', begin), summary.size());
    std::fprintf(stderr, "pomar: repair: %s\n", summary.substr(begin, end - begin).c_str());
    begin = end + 1;
  }
  return seconds;
}

double bpv(uint64_t bytes, uint32_t vertices) {
  return vertices ? 8.0 * double(bytes) / double(vertices) : 0.0;
}

std::string describe_precision(pomar::AttributeKind kind, uint32_t components, int bits,
                               double bound) {
  char text[160];
  if (kind == pomar::AttributeKind::Colour)
    std::snprintf(text, sizeof text, "%s, 8 bits exact", components == 4 ? "RGBA" : "RGB");
  else if (bits == 0)
    std::snprintf(text, sizeof text, "exact floats");
  else if (kind == pomar::AttributeKind::Normal)
    std::snprintf(text, sizeof text, "%d-bit octahedral, error <= %.3g deg", bits, bound);
  else
    std::snprintf(text, sizeof text, "%d bits over its range, error <= %.3g", bits, bound);
  return text;
}

void print_attributes(const pomar::FileInfo &i) {
  for (const pomar::AttributeInfo &a : i.attributes) {
    // (the seam cut's wedge values: per-corner texture coordinates and face materials)
    if (a.name == "pomar:corner texcoord")
      std::printf("  per-corner texture coordinates %.2f bits/vertex (%s)\n",
                  bpv(a.bytes, i.vertices),
                  describe_precision(a.kind, a.components, a.bits, a.bound).c_str());
    else if (a.name == "pomar:face material")
      std::printf("  face materials %.2f bits/vertex (exact)\n", bpv(a.bytes, i.vertices));
    else
      std::printf("  attribute %-10s %-8s %.2f bits/vertex (%s)\n",
                  pomar::printable(a.name).c_str(), pomar::kind_name(a.kind),
                  bpv(a.bytes, i.vertices),
                  describe_precision(a.kind, a.components, a.bits, a.bound).c_str());
  }
  for (size_t t = 0; t < i.texture_files.size(); ++t) {
    const uint64_t embedded = t < i.embedded_texture_bytes.size() ? i.embedded_texture_bytes[t] : 0;
    if (embedded)
      std::printf("  texture file %s (embedded, %llu bytes)\n",
                  pomar::printable(i.texture_files[t]).c_str(),
                  static_cast<unsigned long long>(embedded));
    else
      std::printf("  texture file %s\n", pomar::printable(i.texture_files[t]).c_str());
  }
}

void warn_dropped(const std::string &file, const std::vector<std::string> &what, const char *verb,
                  const char *why) {
  if (what.empty())
    return;
  std::string list;
  for (const auto &s : what)
    list += (list.empty() ? "" : ", ") + s;
  std::fprintf(stderr, "pomar: warning: %s %s %s%s\n", file.c_str(), verb,
               pomar::printable(list).c_str(), why);
}

} // namespace pomar::tool
