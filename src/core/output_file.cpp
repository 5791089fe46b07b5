#include "core/output_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/error.hpp"

namespace seamless {

std::string partial_path(const std::string& path) { return path + ".partial"; }

void commit_partial(const std::string& path) {
  const std::string tmp = partial_path(path);
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw Error("cannot rename '" + tmp + "' to '" + path + "': " + std::strerror(errno));
}

}  // namespace seamless
