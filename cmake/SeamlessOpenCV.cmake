# OpenCV's rgbd contrib module (RgbdOdometry, ICPOdometry, RgbdICPOdometry, FastICPOdometry) for
# the external trackers of src/recon/external/. Debian splits OpenCV: libopencv-contrib-dev ships
# the rgbd headers and libopencv_rgbd.so, but OpenCVConfig.cmake comes only with the meta package
# libopencv-dev, so find_package(OpenCV) fails on a machine that has everything we need. We try the
# config package first and fall back to the headers and libraries themselves. Either way the result
# is the interface target seamless_opencv_rgbd and SEAMLESS_HAS_OPENCV.
macro(seamless_optional_opencv_rgbd)
  option(SEAMLESS_WITH_OPENCV "Use OpenCV's rgbd contrib module if found" ON)
  if(NOT SEAMLESS_WITH_OPENCV)
    seamless_module_status(OPENCV OFF "SEAMLESS_WITH_OPENCV=OFF")
  else()
    find_package(OpenCV QUIET COMPONENTS core imgproc rgbd)
    if(OpenCV_FOUND)
      add_library(seamless_opencv_rgbd INTERFACE)
      target_include_directories(seamless_opencv_rgbd SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})
      target_link_libraries(seamless_opencv_rgbd INTERFACE ${OpenCV_LIBS})
      seamless_module_status(OPENCV ON "OpenCV ${OpenCV_VERSION} (rgbd)")
    else()
      find_path(SEAMLESS_OPENCV_INCLUDE opencv2/rgbd.hpp PATH_SUFFIXES opencv4)
      find_library(SEAMLESS_OPENCV_RGBD_LIB opencv_rgbd)
      find_library(SEAMLESS_OPENCV_IMGPROC_LIB opencv_imgproc)
      find_library(SEAMLESS_OPENCV_CORE_LIB opencv_core)
      if(SEAMLESS_OPENCV_INCLUDE AND SEAMLESS_OPENCV_RGBD_LIB AND SEAMLESS_OPENCV_IMGPROC_LIB AND SEAMLESS_OPENCV_CORE_LIB)
        add_library(seamless_opencv_rgbd INTERFACE)
        target_include_directories(seamless_opencv_rgbd SYSTEM INTERFACE ${SEAMLESS_OPENCV_INCLUDE})
        target_link_libraries(seamless_opencv_rgbd INTERFACE
          ${SEAMLESS_OPENCV_RGBD_LIB} ${SEAMLESS_OPENCV_IMGPROC_LIB} ${SEAMLESS_OPENCV_CORE_LIB})
        seamless_module_status(OPENCV ON "rgbd contrib at ${SEAMLESS_OPENCV_RGBD_LIB} (no OpenCVConfig.cmake)")
      else()
        seamless_module_status(OPENCV OFF "rgbd contrib not found (apt-get install libopencv-contrib-dev)")
      endif()
    endif()
  endif()
endmacro()
