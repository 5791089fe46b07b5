#include "core/cuda_arch.hpp"

namespace seamless {

CudaArchMatch cuda_arch_match(const std::string& archs, int major, int minor) {
  const int cc = major * 10 + minor;
  bool any = false, sass = false, ptx = false;
  std::size_t i = 0;
  while (i < archs.size()) {
    const std::size_t end = archs.find_first_of(" ;,", i);
    const std::string tok = archs.substr(i, end == std::string::npos ? std::string::npos : end - i);
    i = end == std::string::npos ? archs.size() : end + 1;
    std::size_t digits = 0;
    while (digits < tok.size() && tok[digits] >= '0' && tok[digits] <= '9') ++digits;
    if (digits == 0) continue;  // "native", "all", an empty field
    any = true;
    const int n = std::stoi(tok.substr(0, digits));
    const std::string rest = tok.substr(digits);
    const bool specific = !rest.empty() && rest[0] == 'a';  // 90a: sm_90a only (100f: the 10.x family)
    const bool real = rest.find("-virtual") == std::string::npos;
    const bool virt = rest.find("-real") == std::string::npos && !specific;
    if (real && (specific ? n == cc : n / 10 == major && n % 10 <= minor)) sass = true;
    if (virt && n <= cc) ptx = true;
  }
  if (!any) return CudaArchMatch::unknown;
  return sass ? CudaArchMatch::machine_code : ptx ? CudaArchMatch::ptx_only : CudaArchMatch::none;
}

std::string cuda_arch_advice(const std::string& archs, int major, int minor, const std::string& gpu_name) {
  const std::string sm = std::to_string(major) + std::to_string(minor);
  const std::string gpu =
      gpu_name + " (compute capability " + std::to_string(major) + "." + std::to_string(minor) + ", sm_" + sm + ")";
  switch (cuda_arch_match(archs, major, minor)) {
    case CudaArchMatch::none:
      return "this build has no CUDA code for " + gpu + ": it was compiled for the architectures \"" + archs +
             "\"; rebuild with -DSEAMLESS_CUDA_ARCH=" + sm + " (or -DSEAMLESS_CUDA_ARCH=auto on this machine)";
    case CudaArchMatch::ptx_only:
      return "this build has no machine code for " + gpu + " (compiled for \"" + archs +
             "\"): the driver compiles its PTX at start-up, which takes a while the first time; "
             "-DSEAMLESS_CUDA_ARCH=" +
             sm + " (or auto on this machine) builds its machine code";
    default: return "";
  }
}

}  // namespace seamless
