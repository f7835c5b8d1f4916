# Imported targets for the system libraries that have no usable CMake package on Debian, shared by this build and
# the installed package (it is installed next to wiresConfig.cmake, which includes it):
#   wires_deps::epoxy       libepoxy (pkg-config only)
#   wires_deps::stb         Debian's libstb (stb_image, stb_image_write compiled into libstb.so)
#   wires_deps::opensubdiv  OpenSubdiv Far/Osd CPU (Debian's OpenSubdivConfig names static libraries it does not ship)
# Each is defined once (a second find_package(wires) reuses them). Libraries that do ship a working package (glm,
# TBB, nlohmann_json, glfw3, OpenGL) are found through find_package / find_dependency instead.
# Sets wires_deps_missing to the list of what was not found (the caller turns it into an error).
set(wires_deps_missing "")

# wires_deps::<name> from a header (found with the given path suffix, may be empty) and a library; on failure
# `what` goes into wires_deps_missing. The cache variables are WIRES_<NAME>_INCLUDE_DIR and WIRES_<NAME>_LIBRARY.
macro(wires_import_dependency name header suffix library what)
  string(TOUPPER "${name}" _wires_upper)
  if(NOT TARGET wires_deps::${name})
    find_path(WIRES_${_wires_upper}_INCLUDE_DIR ${header} PATH_SUFFIXES ${suffix})
    find_library(WIRES_${_wires_upper}_LIBRARY ${library})
    if(WIRES_${_wires_upper}_INCLUDE_DIR AND WIRES_${_wires_upper}_LIBRARY)
      add_library(wires_deps::${name} UNKNOWN IMPORTED)
      set_target_properties(wires_deps::${name} PROPERTIES
        IMPORTED_LOCATION "${WIRES_${_wires_upper}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${WIRES_${_wires_upper}_INCLUDE_DIR}")
    else()
      list(APPEND wires_deps_missing "${what}")
    endif()
  endif()
endmacro()

wires_import_dependency(epoxy epoxy/gl.h "" epoxy "libepoxy (Debian: libepoxy-dev)")
wires_import_dependency(stb stb_image.h stb stb "stb (Debian: libstb-dev)")
wires_import_dependency(opensubdiv opensubdiv/far/topologyRefiner.h "" osdCPU "OpenSubdiv (Debian: libosd-dev)")
