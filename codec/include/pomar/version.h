// pomar's version. The top-level CMakeLists.txt reads these three numbers for
// project(VERSION), the CMake package's version file, pomar.pc and the shared libraries'
// version: change them here and nowhere else.
//
// A program can check at compile time what it was built against:
//   #if POMAR_VERSION < POMAR_MAKE_VERSION(0, 2, 0) ... #endif
// and at run time what it runs with: pomar::version() (from pomar/pomar.h).
#pragma once

#define POMAR_VERSION_MAJOR 0
#define POMAR_VERSION_MINOR 1
#define POMAR_VERSION_PATCH 0

#define POMAR_MAKE_VERSION(major, minor, patch) ((major)*10000 + (minor)*100 + (patch))
#define POMAR_VERSION                                                                              \
  POMAR_MAKE_VERSION(POMAR_VERSION_MAJOR, POMAR_VERSION_MINOR, POMAR_VERSION_PATCH)
