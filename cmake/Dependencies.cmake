# System dependencies (Debian packages installed by tools/setup.sh). Third-party headers are SYSTEM
# includes so our warning flags do not apply to them.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
find_package(glfw3 3.3 REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(TBB REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)

# Debian's OpenSubdiv CMake config names static libraries that are not installed: make our own target.
find_library(OSD_CPU_LIBRARY osdCPU REQUIRED)
find_path(OSD_INCLUDE_DIR opensubdiv/far/topologyRefiner.h REQUIRED)
add_library(opensubdiv::cpu UNKNOWN IMPORTED)
set_target_properties(opensubdiv::cpu PROPERTIES
  IMPORTED_LOCATION ${OSD_CPU_LIBRARY}
  INTERFACE_SYSTEM_INCLUDE_DIRECTORIES ${OSD_INCLUDE_DIR})

# stb: Debian's libstb ships the implementations (stb_image, stb_image_write) in libstb.so, so no
# translation unit of ours defines STB_*_IMPLEMENTATION.
find_path(STB_INCLUDE_DIR stb_image.h PATHS /usr/include/stb REQUIRED)
find_library(STB_LIBRARY stb REQUIRED)
add_library(third_party_stb INTERFACE)
target_include_directories(third_party_stb SYSTEM INTERFACE ${STB_INCLUDE_DIR})
target_link_libraries(third_party_stb INTERFACE ${STB_LIBRARY})
add_library(third_party::stb ALIAS third_party_stb)

# tinygltf (header-only) includes <stb_image.h> and <nlohmann/json.hpp>. Its implementation is compiled
# once, in engine/assets.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
add_library(tinygltf_headers INTERFACE)
target_include_directories(tinygltf_headers SYSTEM INTERFACE ${TINYGLTF_INCLUDE_DIR})
target_link_libraries(tinygltf_headers INTERFACE nlohmann_json::nlohmann_json third_party::stb)
add_library(third_party::tinygltf ALIAS tinygltf_headers)

if(WIRE_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(WIRE_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
