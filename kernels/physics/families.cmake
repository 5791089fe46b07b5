# seamless_kernel_family(physics/...) lines go here
