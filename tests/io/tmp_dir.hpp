// A temporary folder for one test, removed afterwards.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <string>

struct TmpDir {
  std::filesystem::path path;
  explicit TmpDir(const std::string& tag) {
    path = std::filesystem::temp_directory_path() / ("seamless_io_" + tag + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TmpDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  std::string str() const { return path.string(); }
};
