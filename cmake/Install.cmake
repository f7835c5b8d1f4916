# The installed CMake package (a contract, docs/install.md):
#   cmake --install build --prefix P
# installs the libraries below with their public headers (each target's include/ folder, whole) into P/lib and
# P/include, and P/lib/cmake/wires/{wiresConfig,wiresConfigVersion,wiresTargets,wiresDependencies}.cmake.
# find_package(wires 0.3) then gives the namespaced targets wires::<export name>. Target-based: sources and
# headers added to these targets need no change here. The libraries load nothing from disk at run time (the wire
# shaders are compiled into wire_render).
# Programs: P/bin/wiretool and P/bin/tunnel, with the tunnel's assets in P/share/wires/tunnel (found relative to
# the executable, so the prefix can be moved); the Python module `wires`, when built, in P/<WIRES_PYTHON_INSTALL_DIR>
# (python/CMakeLists.txt). Tests, benchmarks and examples are not installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(WIRES_INSTALL_CMAKEDIR "lib/cmake/wires" CACHE STRING "Where the wires CMake package files are installed")

# target -> export name (wires::<name>). Also ALIASes in this build, so a parent project using
# add_subdirectory() can link the same names.
set(wires_exported
  engine_core:core engine_ecs:ecs engine_scene:scene engine_platform:platform engine_gfx:gfx engine_assets:assets
  wire_core:wire wire_io:wire_io wire_systems:wire_systems wire_render:wire_render curved_space:curved_space)

set(wires_targets "")
foreach(pair IN LISTS wires_exported)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 target)
  list(GET pair 1 export_name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  add_library(wires::${export_name} ALIAS ${target})
  list(APPEND wires_targets ${target})
  # Public headers: the include/ folder next to the target's CMakeLists.txt, every file in it.
  get_target_property(source_dir ${target} SOURCE_DIR)
  install(DIRECTORY ${source_dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

install(TARGETS ${wires_targets}
  EXPORT wiresTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT wiresTargets NAMESPACE wires:: DESTINATION ${WIRES_INSTALL_CMAKEDIR})

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/wiresConfig.cmake.in
  ${CMAKE_BINARY_DIR}/package/wiresConfig.cmake
  INSTALL_DESTINATION ${WIRES_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the API (CHANGELOG.md), so 0.3 accepts only 0.3.x (stricter than
# SameMajorVersion): find_package(wires 0.2) is refused by this 0.3.0 package.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/wiresConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES
  ${CMAKE_BINARY_DIR}/package/wiresConfig.cmake
  ${CMAKE_BINARY_DIR}/package/wiresConfigVersion.cmake
  ${CMAKE_CURRENT_LIST_DIR}/wiresDependencies.cmake
  DESTINATION ${WIRES_INSTALL_CMAKEDIR})

# Programs (docs/install.md): relocatable, they name no path of this machine.
install(TARGETS wiretool tunnel RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${WIRE_ASSET_DIR}/tunnel/ DESTINATION ${TUNNEL_ASSETS_DESTINATION})
