// Shared by the io tests: a temporary folder for one test (removed afterwards), the real data
// folders of ../shared/data, and a check that an error message names something.
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

// A folder of the real test data (../shared/data); REQUIRE_DATA skips a test where it is absent.
inline std::string data_dir(const std::string& name) { return std::string(SEAMLESS_TEST_DATA) + "/" + name; }
#define REQUIRE_DATA(dir) \
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "test data folder " << dir << " is absent"
#define EXPECT_MENTIONS(msg, needle) EXPECT_NE((msg).find(needle), std::string::npos) << (msg)
