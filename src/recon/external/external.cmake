# External trackers (the tracker comparison): OpenCV contrib's rgbd odometries and PCL's
# GICP behind recon/external/odometry.hpp. Each implementation is compiled only when its library
# was found (SEAMLESS_HAS_OPENCV / SEAMLESS_HAS_PCL); odometry.cpp always is and returns an empty
# factory for a missing one, so the registry can say what to install.
add_library(seamless_external_odometry STATIC ${CMAKE_CURRENT_LIST_DIR}/odometry.cpp)
target_link_libraries(seamless_external_odometry PUBLIC seamless_io seamless_core PRIVATE Eigen3::Eigen)
if(SEAMLESS_HAS_OPENCV)
  target_sources(seamless_external_odometry PRIVATE ${CMAKE_CURRENT_LIST_DIR}/opencv_odometry.cpp)
  target_link_libraries(seamless_external_odometry PRIVATE seamless_opencv_rgbd)
endif()
if(SEAMLESS_HAS_PCL)
  target_sources(seamless_external_odometry PRIVATE ${CMAKE_CURRENT_LIST_DIR}/pcl_gicp_odometry.cpp)
  target_include_directories(seamless_external_odometry SYSTEM PRIVATE ${PCL_INCLUDE_DIRS})
  target_compile_definitions(seamless_external_odometry PRIVATE ${PCL_DEFINITIONS})
  target_link_libraries(seamless_external_odometry PRIVATE ${PCL_LIBRARIES})
endif()
