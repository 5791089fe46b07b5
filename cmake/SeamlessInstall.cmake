# install(): `cmake --install build --prefix P` gives P/bin/seamless, the configs and docs under
# P/share/seamless, and the CMake package P/lib/cmake/seamless: find_package(seamless) with the
# imported targets seamless::core, seamless::kernels, seamless::io and seamless::eval (static
# libraries; their headers under P/include/seamless, included as "core/buffer.hpp",
# "eval/trajectory_eval.hpp", ... as inside the tree). tests/install builds a consumer against it.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS seamless RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY configs docs DESTINATION ${CMAKE_INSTALL_DATADIR}/seamless)
install(FILES README.md LICENSE CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DATADIR}/seamless)

set(seamless_include_dir ${CMAKE_INSTALL_INCLUDEDIR}/seamless)
set(seamless_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/seamless)
foreach(lib core kernels io eval)
  set_target_properties(seamless_${lib} PROPERTIES EXPORT_NAME ${lib})
endforeach()
set_target_properties(seamless_flags PROPERTIES EXPORT_NAME flags)
install(TARGETS seamless_flags seamless_core seamless_kernels seamless_io seamless_eval EXPORT seamlessTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(EXPORT seamlessTargets NAMESPACE seamless:: DESTINATION ${seamless_cmake_dir})

# The headers of those libraries, in the tree's layout (core/, io/, eval/, kernels/<layer>/).
foreach(dir src/core src/io src/eval)
  install(DIRECTORY ${dir} DESTINATION ${seamless_include_dir} FILES_MATCHING PATTERN "*.hpp" PATTERN "*.cuh")
endforeach()
install(DIRECTORY kernels DESTINATION ${seamless_include_dir}
  FILES_MATCHING PATTERN "*.hpp" PATTERN "*.inl" PATTERN "*.cuh")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/generated/seamless/build_config.hpp DESTINATION ${seamless_include_dir}/seamless)

configure_package_config_file(cmake/seamlessConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/seamlessConfig.cmake
  INSTALL_DESTINATION ${seamless_cmake_dir})
# Before 1.0 a minor version may break the interface (CHANGELOG.md): same major.minor only.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/seamlessConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/seamlessConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/seamlessConfigVersion.cmake
  DESTINATION ${seamless_cmake_dir})
