# Camera tracking (issue 5): ICP / RGB-D tracker, gravity, the sequence driver, the tracking
# benchmark. See docs/TRACKING.md.
add_library(seamless_tracker STATIC
  ${CMAKE_CURRENT_LIST_DIR}/tracker.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tracker_gravity.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tracker_sequence.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bench_track.cpp)
target_link_libraries(seamless_tracker PUBLIC seamless_preprocess seamless_recon seamless_io seamless_kernels
  PRIVATE Eigen3::Eigen spdlog::spdlog)
