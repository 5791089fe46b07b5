// Small text files of numbers (pose matrices, camera matrices, gravity vectors) as the common
// RGB-D layouts write them.
#pragma once
#include <string>
#include <vector>

namespace seamless {

// Every number of the file: separated by whitespace, commas, semicolons or brackets; '#' starts a
// comment; "inf", "-inf" and "nan" are numbers. A token that is not a number is an InputError
// naming `what`, the file and the line (and `expected`, when given, e.g. "(expected a 3x3 matrix)").
std::vector<double> read_numbers(const std::string& path, const std::string& what, const std::string& expected = "");

}  // namespace seamless
