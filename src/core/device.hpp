// Which backend runs the kernels. Chosen at run time (config `device:`, flag `--device`).
#pragma once
#include <string>

namespace seamless {

enum class Device { CPU, CUDA };

// Parses "cpu", "cuda" or "auto" (auto = CUDA when this build has it and a GPU is present).
// Asking for CUDA in a build without it, or on a machine without a GPU, throws seamless::Error.
Device resolve_device(const std::string& name);
const char* device_name(Device d);
bool cuda_built();                      // this binary was compiled with the CUDA backend
bool cuda_available();                  // ... and a CUDA device is usable right now
std::string cuda_device_description();  // "NVIDIA H100 80GB HBM3 (sm_90, 79 GiB)" or ""

}  // namespace seamless
