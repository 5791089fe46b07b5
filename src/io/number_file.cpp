#include "io/number_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"

namespace seamless {

std::vector<double> read_numbers(const std::string& path, const std::string& what, const std::string& expected) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + what + " '" + path + "': " + std::strerror(errno));
  std::vector<double> v;
  std::string line, token;
  for (int n = 1; std::getline(in, line); ++n) {
    line = line.substr(0, line.find('#'));
    for (char& c : line)
      if (c == ',' || c == ';' || c == '[' || c == ']') c = ' ';
    std::istringstream ss(line);
    while (ss >> token) {
      std::size_t used = 0;
      double x = 0;
      try {
        x = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size())
        throw InputError(what + " '" + path + "' line " + std::to_string(n) + ": '" + token + "' is not a number" +
                         (expected.empty() ? "" : " " + expected));
      v.push_back(x);
    }
  }
  return v;
}

}  // namespace seamless
