# kernels/physics: the unified particle solver (Macklin et al. 2014), see docs/PHYSICS.md.
seamless_kernel_family(physics/solver)
# The CPU instantiation without errno for sqrt: the same results (sqrt of a negative is NaN either
# way), but GCC may then share and vectorise square roots instead of guarding each libm call
# (the SIMD tiles' lane-by-lane square roots become one vector instruction). -Wno-psabi: the tiles
# pass 32-byte vectors between always_inline functions, whose ABI note does not apply.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/physics/solver_cpu.cpp
  PROPERTIES COMPILE_OPTIONS "$<$<CXX_COMPILER_ID:GNU,Clang>:-fno-math-errno;-Wno-psabi;--param=inline-unit-growth=200>")
