// Exit statuses of the pomar tool (README "Exit codes"): one per kind of failure, so that
// scripts can tell a bad mesh from a damaged file from a full disk without reading the
// message. exit_status() is the one place that maps pomar::Error kinds to statuses.
#pragma once

#include "pomar/pomar.h"

namespace pomar::tool {

constexpr int kExitError = 1;       // a pomar::Error without a kind (Kind::Other)
constexpr int kExitUsage = 2;       // a value the command cannot use (level, cluster, size...)
constexpr int kExitMismatch = 3;    // verify: the mesh differs
constexpr int kExitDamaged = 4;     // a damaged or truncated .pomar file; info --check and
                                    // decode --skip-damaged: damaged blocks (output written)
constexpr int kExitInvalidMesh = 5; // a mesh the codec cannot take (or an unreadable mesh file)
constexpr int kExitIo = 6;          // a file that cannot be read or written
constexpr int kExitMemory = 7;      // the memory limit
constexpr int kExitUnsupported = 8; // a .pomar version or section this build does not read
constexpr int kExitInternal = 70;   // EX_SOFTWARE: a broken invariant of the codec (a bug)

/// The exit status for an error of this kind.
int exit_status(const Error &e);

} // namespace pomar::tool
