# kernels/physics: the unified particle solver (Macklin et al. 2014), see docs/PHYSICS.md.
seamless_kernel_family(physics/solver)
# The CPU instantiation without errno for sqrt: the same results (sqrt of a negative is NaN either
# way), but GCC may then share and vectorise square roots instead of guarding each libm call.
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/physics/solver_cpu.cpp
  PROPERTIES COMPILE_OPTIONS "$<$<CXX_COMPILER_ID:GNU,Clang>:-fno-math-errno>")
