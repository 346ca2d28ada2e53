# `cmake --install` for library users: headers, pomar_core / pomar_io (static by default,
# shared with -DBUILD_SHARED_LIBS=ON), the CMake package (find_package(pomar CONFIG) ->
# pomar::core, pomar::io) and pomar.pc for pkg-config. Everything here is in the install
# component "library" (the tool is in the default component), so
#   cmake --install build --component library --prefix /opt/pomar
# installs the library alone (tests/install/consumer_test.sh does that).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(POMAR_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/pomar")
# Every header of codec/include/pomar is public (internals live in codec/src), except the
# MeshLab plugins' boundary headers meshlab_*.h, which need MeshLab's headers of this build.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/codec/include/pomar" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
        COMPONENT library FILES_MATCHING PATTERN "*.h" PATTERN "meshlab_*.h" EXCLUDE)

# Shared libraries: libpomar_core.so.0.1 -> libpomar_core.so.0.1.0. Before 1.0 a minor
# version may change the ABI, so the SONAME carries MAJOR.MINOR.
set(_pomar_libraries pomar_core)
if(TARGET pomar_io)
  list(APPEND _pomar_libraries pomar_io)
endif()
foreach(lib ${_pomar_libraries})
  string(REPLACE "pomar_" "" export_name "${lib}")
  set_target_properties(${lib} PROPERTIES
    EXPORT_NAME ${export_name}
    VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
endforeach()
install(TARGETS ${_pomar_libraries} EXPORT pomarTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT library
        LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT library
        RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT library)
install(EXPORT pomarTargets NAMESPACE pomar:: DESTINATION "${POMAR_CMAKE_DIR}"
        COMPONENT library)

# No dependencies to find: xxhash is inlined, tinyobjloader's and vcglib's PLY code are
# compiled into pomar_io (codec/CMakeLists.txt), so a program links pomar alone.
configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/pomarConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/pomarConfig.cmake" INSTALL_DESTINATION "${POMAR_CMAKE_DIR}")
write_basic_package_version_file("${PROJECT_BINARY_DIR}/pomarConfigVersion.cmake"
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/pomarConfig.cmake"
              "${PROJECT_BINARY_DIR}/pomarConfigVersion.cmake"
        DESTINATION "${POMAR_CMAKE_DIR}" COMPONENT library)

# pkg-config: one package, pomar (pomar_io + pomar_core), relocatable: its prefix is
# found from the .pc file's own directory, so any --prefix of cmake --install works.
if(TARGET pomar_io)
  file(RELATIVE_PATH POMAR_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
  string(REGEX REPLACE "/$" "" POMAR_PC_TO_PREFIX "${POMAR_PC_TO_PREFIX}")
  configure_file("${CMAKE_CURRENT_LIST_DIR}/pomar.pc.in" "${PROJECT_BINARY_DIR}/pomar.pc" @ONLY)
  install(FILES "${PROJECT_BINARY_DIR}/pomar.pc"
          DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig" COMPONENT library)
endif()
