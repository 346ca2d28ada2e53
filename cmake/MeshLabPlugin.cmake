# Building MeshLab 2020.09 plugins against Debian's MeshLab (recipe:
# /work/shared/docs/meshlab-plugins.md): headers from the source package in
# ${POMAR_MESHLAB_SRC} (src/ and vcglib/), the installed libmeshlab-common.so in
# ${POMAR_MESHLAB_LIBDIR}, MESHLAB_SCALAR=float.

# Define the imported target pomar_meshlab_common, or set POMAR_MESHLAB_MISSING to what
# is missing.
function(pomar_find_meshlab)
  find_package(Qt5 5.15 QUIET COMPONENTS Core Gui Widgets OpenGL Xml)
  find_package(Eigen3 3.3 QUIET NO_MODULE)
  find_path(POMAR_GLEW_INCLUDE_DIR GL/glew.h)
  set(missing "")
  if(NOT Qt5_FOUND)
    list(APPEND missing "Qt5 Core/Gui/Widgets/OpenGL/Xml (qtbase5-dev libqt5opengl5-dev)")
  endif()
  if(NOT Eigen3_FOUND)
    list(APPEND missing "Eigen3 (libeigen3-dev)")
  endif()
  if(NOT POMAR_GLEW_INCLUDE_DIR)
    list(APPEND missing "GL/glew.h (libglew-dev)")
  endif()
  if(NOT EXISTS "${POMAR_MESHLAB_SRC}/src/common/interfaces.h")
    list(APPEND missing "MeshLab headers in ${POMAR_MESHLAB_SRC}/src (scripts/setup.sh)")
  endif()
  if(NOT EXISTS "${POMAR_MESHLAB_LIBDIR}/libmeshlab-common.so")
    list(APPEND missing "${POMAR_MESHLAB_LIBDIR}/libmeshlab-common.so (meshlab)")
  endif()
  if(missing)
    list(JOIN missing ", " missing)
    set(POMAR_MESHLAB_MISSING "${missing}" PARENT_SCOPE)
    return()
  endif()
  # MeshLab's shared library with the include roots and flags its headers need (GLOBAL:
  # both plugins and their tests use it).
  add_library(pomar_meshlab_common SHARED IMPORTED GLOBAL)
  set_target_properties(pomar_meshlab_common PROPERTIES
    IMPORTED_LOCATION "${POMAR_MESHLAB_LIBDIR}/libmeshlab-common.so")
  target_include_directories(pomar_meshlab_common SYSTEM INTERFACE
    "${POMAR_MESHLAB_SRC}/src" "${POMAR_MESHLAB_SRC}/vcglib" "${POMAR_GLEW_INCLUDE_DIR}")
  target_compile_definitions(pomar_meshlab_common INTERFACE MESHLAB_SCALAR=float)
  target_link_libraries(pomar_meshlab_common INTERFACE
    Qt5::Core Qt5::Gui Qt5::Widgets Qt5::OpenGL Qt5::Xml Eigen3::Eigen)
endfunction()

# A plugin module linking pomar_core only; what it does besides MeshLab's glue is in the
# plugins' boundary headers codec/include/pomar/meshlab_*.h (found through pomar_core). Its .cpp
# includes its own moc file (one heavy translation unit); installed into MeshLab's plugin directory under the install prefix
# (/usr: Debian's MeshLab finds it).
function(pomar_add_meshlab_plugin target)
  find_package(Qt5 5.15 REQUIRED COMPONENTS Core) # AUTOMOC needs Qt in this scope
  add_library(${target} MODULE ${ARGN})
  set_target_properties(${target} PROPERTIES AUTOMOC ON)
  target_link_libraries(${target} PRIVATE pomar_core pomar_meshlab_common)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  # Fail at link time on a missing symbol; keep pomar_core's symbols out of the dynamic table.
  target_link_options(${target} PRIVATE -Wl,--no-undefined -Wl,--exclude-libs,ALL)
  install(TARGETS ${target} LIBRARY DESTINATION lib/x86_64-linux-gnu/meshlab/plugins)
endfunction()
