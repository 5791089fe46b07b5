// Output files written under a temporary name and renamed when complete: a run that is killed,
// or fails while writing, never leaves a truncated file under the final name, and a file under
// the final name is whole (README, "Exit codes and interrupted runs").
#pragma once
#include <string>

namespace seamless {

// Where a file is written until it is complete: "<path>.partial".
std::string partial_path(const std::string& path);

// Renames partial_path(path) to path (atomic on one file system, replacing an older file).
// Throws seamless::Error naming both paths when the rename fails.
void commit_partial(const std::string& path);

}  // namespace seamless
