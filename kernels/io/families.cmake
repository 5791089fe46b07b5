# kernels/io: the synthetic room's renderer (and input-side image kernels).
seamless_kernel_family(io/render_room)
seamless_kernel_family(io/undistort)
seamless_kernel_family(io/fill_gaps)
seamless_kernel_family(io/kinect_depth)
