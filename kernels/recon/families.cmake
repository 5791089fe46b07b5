seamless_kernel_family(recon/preprocess)
seamless_kernel_family(recon/voxel_hash)
seamless_kernel_family(recon/tsdf_fusion)
seamless_kernel_family(recon/tsdf_raycast)
seamless_kernel_family(recon/icp)
seamless_kernel_family(recon/rgbd)
seamless_kernel_family(recon/tsdf_extract)

# The raycast's march is latency-bound (docs/PERFORMANCE.md): at its natural 76 registers only 3
# blocks of 256 threads fit on an SM; capped at 64, 4 do, and the frame's raycast went from 0.585
# to 0.562 ms on an H200 (56 registers spill and were slower: 0.599).
if(SEAMLESS_HAS_CUDA)
  set_source_files_properties(recon/tsdf_raycast_cuda.cu PROPERTIES COMPILE_OPTIONS "-maxrregcount=64")
endif()
