# install(): `cmake --install build --prefix P` gives P/bin/seamless, the configs and docs under
# P/share/seamless, and the CMake package P/lib/cmake/seamless: find_package(seamless) with the
# imported targets seamless::core, ::kernels, ::io, ::eval, ::config, ::preprocess, ::recon (the
# TSDF volume), ::tracker, ::refine, ::physics (the particle solver) and, when built with OpenGL,
# ::render (static libraries; their headers under P/include/seamless, included as
# "core/buffer.hpp", "recon/volume.hpp", ... as inside the tree). With the Python module built,
# it goes to P/lib/python3/dist-packages/seamless (python/CMakeLists.txt). tests/install builds a
# consumer against it.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS seamless RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY configs docs DESTINATION ${CMAKE_INSTALL_DATADIR}/seamless)
install(FILES README.md LICENSE CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DATADIR}/seamless)

set(seamless_include_dir ${CMAKE_INSTALL_INCLUDEDIR}/seamless)
set(seamless_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/seamless)
# external_odometry: the comparison trackers that seamless::tracker links (OpenCV, PCL when built).
set(seamless_exported core kernels io eval config preprocess recon external_odometry tracker refine physics)
if(SEAMLESS_HAS_GL)
  list(APPEND seamless_exported render)
endif()
set(seamless_export_targets seamless_flags)
foreach(lib IN LISTS seamless_exported)
  set_target_properties(seamless_${lib} PROPERTIES EXPORT_NAME ${lib})
  list(APPEND seamless_export_targets seamless_${lib})
endforeach()
set_target_properties(seamless_flags PROPERTIES EXPORT_NAME flags)
if(TARGET seamless_opencv_rgbd)  # OpenCV's libraries as found (cmake/SeamlessOpenCV.cmake)
  set_target_properties(seamless_opencv_rgbd PROPERTIES EXPORT_NAME opencv_rgbd)
  list(APPEND seamless_export_targets seamless_opencv_rgbd)
endif()
install(TARGETS ${seamless_export_targets} EXPORT seamlessTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(EXPORT seamlessTargets NAMESPACE seamless:: DESTINATION ${seamless_cmake_dir})

# The headers of those libraries, in the tree's layout (core/, io/, recon/, ..., kernels/<layer>/).
foreach(dir src/core src/io src/eval src/config src/recon src/physics src/render)
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
