// What the tool prints on the terminal beyond a command's own report: progress, timings,
// bits per vertex, what a repair changed, attribute precisions, warnings about what a file
// cannot keep.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar::tool {

using Clock = std::chrono::steady_clock;

/// Seconds since `t0`.
double since(Clock::time_point t0);

/// Progress on a terminal: one self-overwriting stderr line; silent otherwise.
Progress terminal_progress(bool quiet);

/// Runs make_manifold() on `mesh` and prints what it changed on stderr, one line per kind
/// of change; "nothing to repair" only when not quiet. Returns the seconds it took.
double repair_and_report(Mesh &mesh, bool quiet);

/// Bits per vertex of `bytes` (0 without vertices).
double bpv(uint64_t bytes, uint32_t vertices);

/// "RGB, 8 bits exact", "9-bit octahedral, error <= 0.332 deg", ...
std::string describe_precision(AttributeKind kind, uint32_t components, int bits, double bound);

/// One line per stored attribute and texture file of `i` (encode's and info's report).
void print_attributes(const FileInfo &i);

/// One stderr warning naming what is lost: `what` is the list, `why` ends the line.
void warn_dropped(const std::string &file, const std::vector<std::string> &what, const char *verb,
                  const char *why);

} // namespace pomar::tool
