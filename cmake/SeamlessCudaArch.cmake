# seamless_resolve_cuda_arch(OUT): the CUDA architectures to build for, from SEAMLESS_CUDA_ARCH.
# `auto` means the GPUs of the configuring machine when there are any (nvidia-smi's compute
# capabilities, e.g. 8.6 -> 86: machine code and PTX for exactly those cards, what CMake's `native`
# gives), provided nvcc can build for them (nvcc --list-gpu-arch); else SEAMLESS_CUDA_ARCH_LIST,
# one build for the common cards. Any other value is taken as given. Says what it chose and why.
function(seamless_resolve_cuda_arch out)
  if(NOT SEAMLESS_CUDA_ARCH STREQUAL "auto")
    set(${out} "${SEAMLESS_CUDA_ARCH}" PARENT_SCOPE)
    return()
  endif()
  set(why "no NVIDIA GPU seen at configure time (nvidia-smi not found)")
  find_program(SEAMLESS_NVIDIA_SMI nvidia-smi)
  set(found "")
  if(SEAMLESS_NVIDIA_SMI)
    execute_process(COMMAND ${SEAMLESS_NVIDIA_SMI} --query-gpu=compute_cap --format=csv,noheader
                    OUTPUT_VARIABLE caps RESULT_VARIABLE rc ERROR_QUIET TIMEOUT 20)
    set(why "no NVIDIA GPU seen at configure time (nvidia-smi --query-gpu=compute_cap found none)")
    if(rc EQUAL 0)
      string(REGEX MATCHALL "[0-9]+\\.[0-9]+" caps "${caps}")
      foreach(cap IN LISTS caps)
        string(REPLACE "." "" sm "${cap}")
        list(APPEND found ${sm})
      endforeach()
      list(REMOVE_DUPLICATES found)
    endif()
  endif()
  if(found)
    # nvcc drops old architectures (CUDA 13 builds 75 and newer): a card it cannot build for gets the list.
    execute_process(COMMAND ${CMAKE_CUDA_COMPILER} --list-gpu-arch OUTPUT_VARIABLE nvcc_archs ERROR_QUIET)
    foreach(sm IN LISTS found)
      if(nvcc_archs AND NOT nvcc_archs MATCHES "compute_${sm}([^0-9]|$)")
        set(why "this machine's GPU is sm_${sm}, which nvcc ${seamless_nvcc_version} cannot build for (that card needs an older CUDA)")
        set(found "")
        break()
      endif()
    endforeach()
  endif()
  if(found)
    message(STATUS "CUDA architectures: ${found} (SEAMLESS_CUDA_ARCH=auto: native, the GPUs of this machine; "
                   "on a machine without a GPU it would be SEAMLESS_CUDA_ARCH_LIST, ${SEAMLESS_CUDA_ARCH_LIST})")
    set(${out} "${found}" PARENT_SCOPE)
  else()
    message(STATUS "CUDA architectures: ${SEAMLESS_CUDA_ARCH_LIST} (SEAMLESS_CUDA_ARCH=auto: ${why}; "
                   "the common cards, SEAMLESS_CUDA_ARCH_LIST)")
    set(${out} "${SEAMLESS_CUDA_ARCH_LIST}" PARENT_SCOPE)
  endif()
endfunction()
