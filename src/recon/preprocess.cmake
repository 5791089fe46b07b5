# Depth preprocessing (host side of kernels/recon/preprocess): used by the trackers and the app.
add_library(seamless_preprocess STATIC ${CMAKE_CURRENT_LIST_DIR}/preprocess.cpp)
target_link_libraries(seamless_preprocess PUBLIC seamless_kernels)
