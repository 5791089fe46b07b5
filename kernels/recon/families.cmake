seamless_kernel_family(recon/preprocess)
seamless_kernel_family(recon/voxel_hash)
seamless_kernel_family(recon/tsdf_fusion)
seamless_kernel_family(recon/tsdf_raycast)
seamless_kernel_family(recon/icp)
seamless_kernel_family(recon/rgbd)
seamless_kernel_family(recon/tsdf_extract)
seamless_kernel_family(recon/dynamic)

# The raycast's march is latency-bound (docs/PERFORMANCE.md, docs/RECONSTRUCTION.md). Register
# cap for this translation unit, measured on an H200 (frame medians of 3 invocations): 64 beat the
# natural 76 before the window's corner lookups (raycast 0.585 -> 0.562 ms); with them, 72 (no
# spills) beats 64 (spills): frame 0.639 -> 0.623 ms.
if(SEAMLESS_HAS_CUDA)
  set_source_files_properties(recon/tsdf_raycast_cuda.cu PROPERTIES COMPILE_OPTIONS "-maxrregcount=72")
endif()

# The bilateral filter's lane loops (kernels/recon/preprocess.inl, bilateral_run) become vector
# instructions only where GCC may evaluate both sides of a float select: -fno-trapping-math
# (floating-point exceptions are never trapped or read here; no value changes).
set_source_files_properties(recon/preprocess_cpu.cpp PROPERTIES COMPILE_OPTIONS
  "$<$<CXX_COMPILER_ID:GNU,Clang>:-fno-trapping-math>")

# The CPU's fusion rows, raycast march and ICP terms on SIMD lanes (kernels/recon/tsdf_fusion_simd.hpp,
# tsdf_march_simd.hpp, icp_simd.hpp; never compiled by nvcc).
# -Wno-psabi: 32-byte vectors pass between always_inline functions, whose ABI note does not apply.
target_sources(seamless_kernels PRIVATE recon/tsdf_fusion_simd.cpp recon/tsdf_march_simd.cpp recon/icp_simd.cpp)
set_source_files_properties(recon/tsdf_fusion_simd.cpp recon/tsdf_march_simd.cpp recon/icp_simd.cpp PROPERTIES COMPILE_OPTIONS
  "$<$<CXX_COMPILER_ID:GNU,Clang>:-Wno-psabi>")
