// The version this library was built as (pomar/version.h may differ in a program that
// compiled against other headers than the library it runs with).
#include <pomar/pomar.h>

namespace pomar {

#define POMAR_STRINGIFY_(x) #x
#define POMAR_STRINGIFY(x) POMAR_STRINGIFY_(x)

const char *version() {
  return POMAR_STRINGIFY(POMAR_VERSION_MAJOR) "." POMAR_STRINGIFY(
      POMAR_VERSION_MINOR) "." POMAR_STRINGIFY(POMAR_VERSION_PATCH);
}

} // namespace pomar
