// CUDA instantiation of the hash stress run (compiled only in CUDA builds).
#include "core/exec_cuda.cuh"
#include "hash_stress.inl"

namespace seamless::test {
StressResult hash_stress_cuda(const std::vector<kernels::HashKey>& ops, const std::vector<kernels::HashKey>& unique,
                              std::int64_t slots) {
  return hash_stress(CudaExec{}, ops, unique, slots);
}
}  // namespace seamless::test
