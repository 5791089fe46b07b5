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
// a named enum (below), std::vector of those, nested structs with visit(), and std::vector of
// such structs. The optional last argument is a Range (numbers, inclusive) or Choices (strings).
//
// A config choice is an enum class with a name table found by argument-dependent lookup; YAML,
// --set, the effective config and error messages use the names, code compares the enum:
//
//   enum class Layout { hash, dense };
//   inline std::span<const EnumName<Layout>> enum_names(Layout) {
//     static constexpr EnumName<Layout> names[] = {{Layout::hash, "hash"}, {Layout::dense, "dense"}};
//     return names;
//   }
//   ...  v("layout", layout, "volume layout");  // the allowed values come from the table
#pragma once
#include <concepts>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace seamless {

struct Range {
  double lo, hi;
};

struct Choices {
  std::vector<std::string> values;
  Choices(std::initializer_list<const char*> v) : values(v.begin(), v.end()) {}
  explicit Choices(std::vector<std::string> v) : values(std::move(v)) {}
};

template <class E> struct EnumName {
  E value;
  const char* name;
};

template <class E>
concept NamedEnum = std::is_enum_v<E> && requires(E e) {
  { enum_names(e) } -> std::convertible_to<std::span<const EnumName<E>>>;
};

// The YAML name of `e` ("?" for a value missing from its table, which enum_names_test catches).
template <NamedEnum E> const char* enum_name(E e) {
  for (const auto& n : enum_names(E{}))
    if (n.value == e) return n.name;
  return "?";
}

// Sets `out` to the value named `name`; false (out unchanged) when no value has that name.
template <NamedEnum E> bool enum_from_name(std::string_view name, E& out) {
  for (const auto& n : enum_names(E{}))
    if (name == n.name) return out = n.value, true;
  return false;
}

// The allowed names in table order, as Choices for messages and docs.
template <NamedEnum E> Choices enum_choices() {
  std::vector<std::string> names;
  for (const auto& n : enum_names(E{})) names.emplace_back(n.name);
  return Choices(std::move(names));
}

}  // namespace seamless
