#include "exit_codes.h"

namespace pomar::tool {

int exit_status(const Error &e) {
  using Kind = Error::Kind;
  switch (e.kind()) {
  case Kind::Usage:
    return kExitUsage;
  case Kind::DamagedFile:
  case Kind::TruncatedFile:
    return kExitDamaged;
  case Kind::InvalidMesh:
    return kExitInvalidMesh;
  case Kind::Io:
    return kExitIo;
  case Kind::MemoryLimit:
    return kExitMemory;
  case Kind::Unsupported:
    return kExitUnsupported;
  case Kind::Internal:
    return kExitInternal;
  default:
    return kExitError;
  }
}

} // namespace pomar::tool
