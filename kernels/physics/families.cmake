# kernels/physics: the unified particle solver (Macklin et al. 2014), see docs/PHYSICS.md.
seamless_kernel_family(physics/solver)
