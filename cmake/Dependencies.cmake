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

# epoxy, stb and OpenSubdiv have no working CMake package on Debian: wiresDependencies.cmake (installed with our
# package too) makes imported targets wires_deps::epoxy, wires_deps::stb, wires_deps::opensubdiv.
include(wiresDependencies)
if(wires_deps_missing)
  message(FATAL_ERROR "missing system libraries: ${wires_deps_missing} (run tools/setup.sh)")
endif()
# Older names, kept for code that links them. stb: Debian's libstb ships the implementations (stb_image,
# stb_image_write) in libstb.so, so no translation unit of ours defines STB_*_IMPLEMENTATION.
add_library(opensubdiv::cpu ALIAS wires_deps::opensubdiv)
set(STB_INCLUDE_DIR ${WIRES_STB_INCLUDE_DIR})
add_library(third_party::stb ALIAS wires_deps::stb)

# tinygltf (header-only) includes <stb_image.h> and <nlohmann/json.hpp>. Its implementation is compiled
# once, in engine/assets.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
add_library(tinygltf_headers INTERFACE)
target_include_directories(tinygltf_headers SYSTEM INTERFACE ${TINYGLTF_INCLUDE_DIR})
target_link_libraries(tinygltf_headers INTERFACE nlohmann_json::nlohmann_json wires_deps::stb)
add_library(third_party::tinygltf ALIAS tinygltf_headers)

if(WIRE_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(WIRE_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
