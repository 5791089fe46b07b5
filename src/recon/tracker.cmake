# Camera tracking: ICP / RGB-D tracker, gravity, the sequence driver, the tracking
# benchmark, and the external trackers of the comparison (src/recon/external/). See docs/TRACKING.md.
include(${CMAKE_CURRENT_LIST_DIR}/external/external.cmake)
add_library(seamless_tracker STATIC
  ${CMAKE_CURRENT_LIST_DIR}/tracker.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tracker_gravity.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tracker_sequence.cpp
  ${CMAKE_CURRENT_LIST_DIR}/tracking_session.cpp
  ${CMAKE_CURRENT_LIST_DIR}/mask_score.cpp
  ${CMAKE_CURRENT_LIST_DIR}/bench_track.cpp)
target_link_libraries(seamless_tracker PUBLIC seamless_preprocess seamless_recon seamless_io seamless_kernels
  seamless_external_odometry PRIVATE Eigen3::Eigen spdlog::spdlog)
