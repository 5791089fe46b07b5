// Helpers of the libFuzzer targets (tests/fuzz/README.md): the readers take file names, so each
// input is written into a scratch folder of this process first.
#pragma once
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace seamless::fuzz {

// This process's scratch folder (libFuzzer runs inputs one after another in one process), removed
// at exit. The log is off: the readers' warnings would cost more than the parsing.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    spdlog::set_level(spdlog::level::off);
    std::string tmpl = (std::filesystem::temp_directory_path() / "seamless_fuzz_XXXXXX").string();
    if (!mkdtemp(tmpl.data())) std::abort();
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratch(), ec);
    });
    return std::filesystem::path(tmpl);
  }();
  return dir;
}

// Writes `data` to scratch()/name (folders made as needed) and returns the path.
inline std::string put(const std::string& name, std::string_view data) {
  std::filesystem::path p = scratch() / name;
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary).write(data.data(), static_cast<std::streamsize>(data.size()));
  return p.string();
}

// A fresh, empty folder scratch()/name.
inline std::string fresh_folder(const std::string& name) {
  std::filesystem::path p = scratch() / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p.string();
}

// The input cut into at most n parts at each line "--8<--" (the seed corpora are readable text
// files with one part per file of the layout); missing parts are empty.
inline std::vector<std::string_view> parts(const std::uint8_t* data, std::size_t size, std::size_t n) {
  std::string_view s(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view cut = "\n--8<--\n";
  std::vector<std::string_view> out;
  while (out.size() + 1 < n) {
    std::size_t at = s.find(cut);
    if (at == std::string_view::npos) break;
    out.push_back(s.substr(0, at));
    s.remove_prefix(at + cut.size());
  }
  out.push_back(s);
  out.resize(n);
  return out;
}

// A property a reader's result must have and did not (not a seamless::Error: it is a bug).
struct Violation : std::logic_error {
  using std::logic_error::logic_error;
};

// Runs f; a seamless::Error (bad input, with a message) is the expected outcome of most inputs.
// Anything else escapes and libFuzzer reports it as a crash: a reader must never let a std::
// exception of its parsing (std::stoi's invalid_argument, say) or a crash through.
template <class F> void expect_error_or_success(F&& f) {
  try {
    f();
  } catch (const seamless::Error&) {
  }
}

}  // namespace seamless::fuzz
