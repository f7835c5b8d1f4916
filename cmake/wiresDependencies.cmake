# Imported targets for the system libraries that have no usable CMake package on Debian, shared by this build and
# the installed package (it is installed next to wiresConfig.cmake, which includes it):
#   wires_deps::epoxy       libepoxy (pkg-config only)
#   wires_deps::stb         Debian's libstb (stb_image, stb_image_write compiled into libstb.so)
#   wires_deps::opensubdiv  OpenSubdiv Far/Osd CPU (Debian's OpenSubdivConfig names static libraries it does not ship)
# Each is defined once (a second find_package(wires) reuses them). Libraries that do ship a working package (glm,
# TBB, nlohmann_json, glfw3, OpenGL) are found through find_package / find_dependency instead.
# Sets wires_deps_missing to the list of what was not found (the caller turns it into an error).
set(wires_deps_missing "")

if(NOT TARGET wires_deps::epoxy)
  find_path(WIRES_EPOXY_INCLUDE_DIR epoxy/gl.h)
  find_library(WIRES_EPOXY_LIBRARY epoxy)
  if(WIRES_EPOXY_INCLUDE_DIR AND WIRES_EPOXY_LIBRARY)
    add_library(wires_deps::epoxy UNKNOWN IMPORTED)
    set_target_properties(wires_deps::epoxy PROPERTIES
      IMPORTED_LOCATION "${WIRES_EPOXY_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${WIRES_EPOXY_INCLUDE_DIR}")
  else()
    list(APPEND wires_deps_missing "libepoxy (Debian: libepoxy-dev)")
  endif()
endif()

if(NOT TARGET wires_deps::stb)
  find_path(WIRES_STB_INCLUDE_DIR stb_image.h PATH_SUFFIXES stb)
  find_library(WIRES_STB_LIBRARY stb)
  if(WIRES_STB_INCLUDE_DIR AND WIRES_STB_LIBRARY)
    add_library(wires_deps::stb UNKNOWN IMPORTED)
    set_target_properties(wires_deps::stb PROPERTIES
      IMPORTED_LOCATION "${WIRES_STB_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${WIRES_STB_INCLUDE_DIR}")
  else()
    list(APPEND wires_deps_missing "stb (Debian: libstb-dev)")
  endif()
endif()

if(NOT TARGET wires_deps::opensubdiv)
  find_path(WIRES_OSD_INCLUDE_DIR opensubdiv/far/topologyRefiner.h)
  find_library(WIRES_OSD_CPU_LIBRARY osdCPU)
  if(WIRES_OSD_INCLUDE_DIR AND WIRES_OSD_CPU_LIBRARY)
    add_library(wires_deps::opensubdiv UNKNOWN IMPORTED)
    set_target_properties(wires_deps::opensubdiv PROPERTIES
      IMPORTED_LOCATION "${WIRES_OSD_CPU_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${WIRES_OSD_INCLUDE_DIR}")
  else()
    list(APPEND wires_deps_missing "OpenSubdiv (Debian: libosd-dev)")
  endif()
endif()
