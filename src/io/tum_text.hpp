#pragma once
// The line loop of the TUM benchmark's text files (rgb.txt, depth.txt, associations.txt,
// accelerometer.txt, groundtruth.txt and trajectories): blank lines and '#' comments are skipped, and
// errors name the file and line. Internal to io (the TUM source and the trajectory reader).
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "core/error.hpp"

namespace seamless::tum_text {

// "'PATH' line N", for error messages.
inline std::string where(const std::string& path, int line) { return "'" + path + "' line " + std::to_string(line); }

// Blank (spaces, tabs, a CR) or a '#' comment.
inline bool is_comment(const std::string& line) {
  auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

// Calls fn(line, n) for each line of the file that is neither blank nor a comment (n: its number
// from 1); `what` names the kind of file in the error when it cannot be opened.
template <class F> void for_each_data_line(const std::string& path, const char* what, F fn) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + std::string(what) + " file '" + path + "': " + std::strerror(errno));
  std::string line;
  for (int n = 1; std::getline(in, line); ++n)
    if (!is_comment(line)) fn(line, n);
}

}  // namespace seamless::tum_text
