# kernels/physics: the unified particle solver (Macklin et al. 2014), see docs/PHYSICS.md and
# kernels/physics/solver.hpp (the passes in order).
foreach(family grid contacts fluid solids integration depth_colliders anisotropy)
  seamless_kernel_family(physics/${family})
endforeach()
# The anisotropic kernels' neighbour walk is latency-bound: capped at 40 registers (from 46), six
# blocks of 256 threads fit a multiprocessor instead of five, at the cost of a few spilled words
# (docs/PERFORMANCE.md, "The anisotropic kernels' cost").
if(SEAMLESS_HAS_CUDA)
  set_source_files_properties(physics/anisotropy_cuda.cu PROPERTIES COMPILE_OPTIONS "-maxrregcount=40")
endif()
# The CPU's SIMD tiles (never compiled by nvcc).
target_sources(seamless_kernels PRIVATE physics/cpu_tiles.cpp)
# The CPU instantiations without errno for sqrt: the same results (sqrt of a negative is NaN either
# way), but GCC may then share and vectorise square roots instead of guarding each libm call
# (the SIMD tiles' lane-by-lane square roots become one vector instruction). -Wno-psabi: the tiles
# pass 32-byte vectors between always_inline functions, whose ABI note does not apply. On every
# physics CPU file, as when they were one file (solver_cpu.cpp), so the scalar loops compile as
# they did.
set(SEAMLESS_PHYSICS_CPU_SOURCES physics/cpu_tiles.cpp physics/grid_cpu.cpp physics/contacts_cpu.cpp
  physics/fluid_cpu.cpp physics/solids_cpu.cpp physics/integration_cpu.cpp physics/anisotropy_cpu.cpp)
list(TRANSFORM SEAMLESS_PHYSICS_CPU_SOURCES PREPEND ${CMAKE_CURRENT_SOURCE_DIR}/)
set_source_files_properties(${SEAMLESS_PHYSICS_CPU_SOURCES}
  PROPERTIES COMPILE_OPTIONS "$<$<CXX_COMPILER_ID:GNU,Clang>:-fno-math-errno;-Wno-psabi;--param=inline-unit-growth=200>")
# A gcc sanitizer build (-DSEAMLESS_SANITIZE; scripts/sanitize builds with clang, whose ASan and
# UBSan leave the tiles matching, see docs/USAGE.md): GCC 12's instrumentation changes what the AVX2 tiles
# compute: use-after-scope on every physics CPU file, and UBSan's checks on cpu_tiles.cpp (a fluid
# at rest then leaves its box, and the tiles no longer match the scalar loops bit for bit), while
# no check reports anything and the uninstrumented -O2 build, ASan alone and valgrind's memcheck of
# the tiles all agree with the scalar loops. Turning off UBSan's sub-checks one at a time (bounds,
# alignment, object-size, signed-integer-overflow) does not restore them. So the physics CPU files
# keep ASan's heap, global and stack bounds checks but not use-after-scope, and the tiles file is
# not built with UBSan; the scalar loops (the same pair terms, particle_math.hpp) are (README.md,
# "Tests").
if(SEAMLESS_SANITIZE MATCHES "address")
  set_property(SOURCE ${SEAMLESS_PHYSICS_CPU_SOURCES} APPEND PROPERTY COMPILE_OPTIONS
    $<$<CXX_COMPILER_ID:GNU>:-fno-sanitize-address-use-after-scope>)
endif()
if(SEAMLESS_SANITIZE MATCHES "undefined")
  set_property(SOURCE ${CMAKE_CURRENT_SOURCE_DIR}/physics/cpu_tiles.cpp APPEND PROPERTY COMPILE_OPTIONS
    $<$<CXX_COMPILER_ID:GNU>:-fno-sanitize=undefined>)
endif()
