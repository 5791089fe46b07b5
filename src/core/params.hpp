// Parameter structs describe their fields to a visitor, so that one declaration gives the typed
// default, the documentation, the range check, YAML loading and the effective-config dump
// (src/config implements the visitors; core and the layers need no YAML).
//
//   struct VolumeParams {
//     float voxel_size = 0.005f;
//     std::string mode = "hash";
//     template <class V> void visit(V& v) {
//       v("voxel_size", voxel_size, "voxel edge, metres", Range{0.001, 1.0});
//       v("mode", mode, "volume layout", Choices{"hash", "dense"});
//     }
//   };
//
// Field types a visitor understands: bool, int, std::int64_t, float, double, std::string, vec3,
// std::vector of those, nested structs with visit(), and std::vector of such structs.
// The optional last argument is a Range (numbers, inclusive) or Choices (strings).
#pragma once
#include <initializer_list>
#include <string>
#include <vector>

namespace seamless {

struct Range {
  double lo, hi;
};

struct Choices {
  std::vector<std::string> values;
  Choices(std::initializer_list<const char*> v) : values(v.begin(), v.end()) {}
};

}  // namespace seamless
