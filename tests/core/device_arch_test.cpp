// Which CUDA architectures of a build run on which GPU (core/cuda_arch.hpp), by CUDA's compatibility
// rules (CUDA C++ Programming Guide, "Binary Compatibility" and "PTX Compatibility"): machine code
// for sm_XY runs on X.Z, Z >= Y; PTX for compute_XY on any later compute capability.
#include <gtest/gtest.h>

#include "core/cuda_arch.hpp"

using namespace seamless;

namespace {
// The default list of SEAMLESS_CUDA_ARCH=auto without a GPU (CMakeLists.txt), as device.cpp gets it.
const std::string kList = "75-real 80-real 86-real 89-real 90";
}  // namespace

TEST(CudaArch, TheDefaultListCoversTheCommonCards) {
  EXPECT_EQ(cuda_arch_match(kList, 7, 5), CudaArchMatch::machine_code);  // T4
  EXPECT_EQ(cuda_arch_match(kList, 8, 6), CudaArchMatch::machine_code);  // RTX 30xx
  EXPECT_EQ(cuda_arch_match(kList, 8, 7), CudaArchMatch::machine_code);  // Orin: sm_86 code, same major
  EXPECT_EQ(cuda_arch_match(kList, 9, 0), CudaArchMatch::machine_code);  // H100
  EXPECT_EQ(cuda_arch_match(kList, 10, 0), CudaArchMatch::ptx_only);     // B200: compute_90 PTX
  EXPECT_EQ(cuda_arch_match(kList, 12, 0), CudaArchMatch::ptx_only);     // RTX 50xx
  EXPECT_EQ(cuda_arch_match(kList, 7, 0), CudaArchMatch::none);          // V100: older than every entry
}

TEST(CudaArch, RealVirtualAndArchSpecificEntries) {
  EXPECT_EQ(cuda_arch_match("90-real", 10, 0), CudaArchMatch::none);  // no PTX to compile
  EXPECT_EQ(cuda_arch_match("90", 10, 0), CudaArchMatch::ptx_only);
  EXPECT_EQ(cuda_arch_match("86-virtual", 8, 6), CudaArchMatch::ptx_only);
  EXPECT_EQ(cuda_arch_match("86-virtual", 8, 0), CudaArchMatch::none);  // PTX runs only forward
  EXPECT_EQ(cuda_arch_match("80;86", 8, 9), CudaArchMatch::machine_code);
  EXPECT_EQ(cuda_arch_match("90a", 9, 0), CudaArchMatch::machine_code);
  EXPECT_EQ(cuda_arch_match("90a", 10, 0), CudaArchMatch::none);    // arch-specific: no PTX, no other card
  EXPECT_EQ(cuda_arch_match("86", 9, 0), CudaArchMatch::ptx_only);  // another major: PTX only
  EXPECT_EQ(cuda_arch_match("native", 9, 0), CudaArchMatch::unknown);
  EXPECT_EQ(cuda_arch_match("", 9, 0), CudaArchMatch::unknown);
}

TEST(CudaArch, AdviceNamesTheArchitectureToRebuildWith) {
  const std::string none = cuda_arch_advice(kList, 7, 0, "Tesla V100");
  EXPECT_NE(none.find("Tesla V100 (compute capability 7.0, sm_70)"), std::string::npos) << none;
  EXPECT_NE(none.find("-DSEAMLESS_CUDA_ARCH=70"), std::string::npos) << none;
  EXPECT_NE(none.find(kList), std::string::npos) << none;
  const std::string ptx = cuda_arch_advice(kList, 12, 0, "RTX 5090");
  EXPECT_NE(ptx.find("compiles its PTX at start-up"), std::string::npos) << ptx;
  EXPECT_NE(ptx.find("-DSEAMLESS_CUDA_ARCH=120"), std::string::npos) << ptx;
  EXPECT_EQ(cuda_arch_advice(kList, 8, 6, "RTX 3090"), "");  // its machine code is there
}
