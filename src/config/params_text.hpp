// Visitors over parameter structs (core/params.hpp) that need no YAML library: the field-type
// classification shared by all visitors, the YAML *writer* (effective config with the doc strings
// as comments), the key lister (docs, did-you-mean) and the flattener (exact comparison).
// The YAML *reader* is in config/params_yaml.hpp.
#pragma once
#include <concepts>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless::config {

// ---- Field-type classification ---------------------------------------------------------------

struct ProbeVisitor {
  template <class... A> void operator()(A&&...) {}
};
template <class T>
concept Visitable = requires(T& t, ProbeVisitor& p) {
  t.visit(p);
};
template <class T>
concept Integer = std::integral<T> && !std::same_as<T, bool>;
// A leaf is one YAML value: a scalar (a named enum is a string from its table), or vec3 as a
// 3-element sequence.
template <class T>
concept Leaf = std::same_as<T, bool> || Integer<T> || std::floating_point<T> || std::same_as<T, std::string> ||
    std::same_as<T, vec3> || NamedEnum<T>;

template <class T> struct VectorOf { using type = void; };
template <class T> struct VectorOf<std::vector<T>> { using type = T; };
template <class T>
concept LeafVector = Leaf<typename VectorOf<T>::type>;
template <class T>
concept SectionVector = Visitable<typename VectorOf<T>::type>;

// "float", "int64", "list of int", ... for docs and error messages.
template <class T> std::string type_name() {
  if constexpr (std::same_as<T, bool>) return "bool";
  else if constexpr (std::same_as<T, int>) return "int";
  else if constexpr (Integer<T> && std::is_signed_v<T>) return "int" + std::to_string(8 * sizeof(T));
  else if constexpr (Integer<T>) return "uint" + std::to_string(8 * sizeof(T));
  else if constexpr (std::same_as<T, float>) return "float";
  else if constexpr (std::same_as<T, double>) return "double";
  else if constexpr (std::same_as<T, std::string> || NamedEnum<T>) return "string";
  else if constexpr (std::same_as<T, vec3>) return "vec3";
  else if constexpr (LeafVector<T>) return "list of " + type_name<typename VectorOf<T>::type>();
  else if constexpr (SectionVector<T>) return "list of sections";
  else if constexpr (Visitable<T>) return "section";
  else static_assert(sizeof(T) == 0, "unsupported parameter field type (see core/params.hpp)");
}

// ---- Text of values (shared by writer, lister, flattener and error messages) ------------------

// Shortest text that reads back to exactly the same value (std::to_chars), so the effective
// config round-trips bit for bit.
std::string format_number(double v);
std::string format_number(float v);
std::string format_bool(bool v);
// Plain when unambiguous (identifiers, paths), otherwise double-quoted with escapes.
std::string format_string(const std::string& s);
std::string format_vec3(vec3 v);
// " [lo, hi]" / " (a | b | c)": the constraint as written in comments and docs.
std::string constraint_text();
std::string constraint_text(const Range& r);
std::string constraint_text(const Choices& c);
// The constraint of a field of type T: a named enum's allowed names, else the one passed (if any).
template <class T, class... C> std::string field_constraint_text(const C&... c) {
  if constexpr (NamedEnum<T>) return constraint_text(enum_choices<T>());
  else return constraint_text(c...);
}

template <class T> std::string format_value(const T& v) {
  if constexpr (std::same_as<T, bool>) return format_bool(v);
  else if constexpr (Integer<T>) return std::to_string(v);
  else if constexpr (std::floating_point<T>) return format_number(v);
  else if constexpr (std::same_as<T, std::string>) return format_string(v);
  else if constexpr (std::same_as<T, vec3>) return format_vec3(v);
  else if constexpr (NamedEnum<T>) return format_string(enum_name(v));
  else {
    static_assert(LeafVector<T>, "format_value: leaf or list of leaves");
    std::string s = "[";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format_value(v[i]);
    return s + "]";
  }
}

// ---- Writer: YAML text with every key and its doc string as a comment --------------------------

class YamlWriter {
 public:
  // `indent` spaces before each key; the first line uses `lead` instead (a "- " list item).
  YamlWriter(std::string& out, int indent, std::string lead = {})
      : out_(out), pad_(indent, ' '), lead_(std::move(lead)) {}

  template <class T, class... C> void operator()(const char* name, T& field, const char* doc, const C&... c) {
    if constexpr (Visitable<T>) {
      line(std::string(name) + ":", doc);
      YamlWriter nested(out_, static_cast<int>(pad_.size()) + 2);
      field.visit(nested);
    } else if constexpr (SectionVector<T>) {
      line(std::string(name) + (field.empty() ? ": []" : ":"), doc);
      for (auto& element : field) {
        YamlWriter item(out_, static_cast<int>(pad_.size()) + 4, pad_ + "  - ");
        element.visit(item);
      }
    } else {
      line(std::string(name) + ": " + format_value(field), doc + field_constraint_text<T>(c...));
    }
  }

 private:
  void line(const std::string& text, const std::string& comment) {
    out_ += lead_.empty() ? pad_ : lead_;
    lead_.clear();
    out_ += text;
    if (!comment.empty()) out_ += "  # " + comment;
    out_ += '\n';
  }
  std::string& out_;
  std::string pad_, lead_;
};

// Every key of P, defaults included, as YAML text with comments. Loads back to an equal P.
template <class P> std::string params_to_yaml(const P& p) {
  P copy = p;  // visit() is non-const by convention; the writer only reads
  std::string out;
  YamlWriter w(out, 0);
  copy.visit(w);
  return out;
}

// ---- Key lister -------------------------------------------------------------------------------

struct KeyInfo {
  std::string path;   // "volume.voxel_size"; list elements as "spawn[].kind"
  std::string type;   // "float", "section", "list of int", ...
  std::string value;  // default (or current) value as YAML text; empty for sections
  std::string doc;
  std::string constraint;  // "[0.0005, 1]", "(hash | dense)" or empty
};

class KeyLister {
 public:
  KeyLister(std::vector<KeyInfo>& out, std::string prefix) : out_(out), prefix_(std::move(prefix)) {}

  template <class T, class... C> void operator()(const char* name, T& field, const char* doc, const C&... c) {
    std::string path = prefix_.empty() ? name : prefix_ + "." + name;
    std::string cons = field_constraint_text<T>(c...);
    if (!cons.empty()) cons.erase(0, 1);  // drop the separating space
    if constexpr (Visitable<T>) {
      out_.push_back({path, type_name<T>(), "", doc, ""});
      KeyLister nested(out_, path);
      field.visit(nested);
    } else if constexpr (SectionVector<T>) {
      out_.push_back({path, type_name<T>(), field.empty() ? "[]" : "", doc, ""});
      typename VectorOf<T>::type element{};
      KeyLister nested(out_, path + "[]");
      element.visit(nested);
    } else {
      out_.push_back({path, type_name<T>(), format_value(field), doc, cons});
    }
  }

 private:
  std::vector<KeyInfo>& out_;
  std::string prefix_;
};

template <class P> std::vector<KeyInfo> list_keys(const P& p = P{}) {
  P copy = p;
  std::vector<KeyInfo> keys;
  KeyLister lister(keys, "");
  copy.visit(lister);
  return keys;
}

// ---- Flattener: (path, exact value text) for every leaf; list elements as "spawn.0.kind" -------

class Flattener {
 public:
  using Entries = std::vector<std::pair<std::string, std::string>>;
  Flattener(Entries& out, std::string prefix) : out_(out), prefix_(std::move(prefix)) {}

  template <class T, class... C> void operator()(const char* name, T& field, const char*, const C&...) {
    std::string path = prefix_.empty() ? name : prefix_ + "." + name;
    if constexpr (Visitable<T>) {
      Flattener nested(out_, path);
      field.visit(nested);
    } else if constexpr (SectionVector<T>) {
      out_.push_back({path + ".size", std::to_string(field.size())});
      for (std::size_t i = 0; i < field.size(); ++i) {
        Flattener nested(out_, path + "." + std::to_string(i));
        field[i].visit(nested);
      }
    } else {
      out_.push_back({path, format_value(field)});
    }
  }

 private:
  Entries& out_;
  std::string prefix_;
};

template <class P> Flattener::Entries flatten(const P& p) {
  P copy = p;
  Flattener::Entries entries;
  Flattener f(entries, "");
  copy.visit(f);
  return entries;
}

// Keys whose values differ, as "path: a -> b" lines; empty when a and b are equal. Values are
// compared through their shortest round-trip text, which is exact (distinct floats never share it).
template <class P> std::vector<std::string> diff_params(const P& a, const P& b) {
  auto fa = flatten(a), fb = flatten(b);
  std::vector<std::string> diffs;
  std::size_t n = fa.size() < fb.size() ? fa.size() : fb.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (fa[i].first != fb[i].first) {  // lists of sections of different length: paths diverge
      diffs.push_back("structure differs at " + fa[i].first + " / " + fb[i].first);
      break;
    }
    if (fa[i].second != fb[i].second) diffs.push_back(fa[i].first + ": " + fa[i].second + " -> " + fb[i].second);
  }
  if (fa.size() != fb.size() && diffs.empty()) diffs.push_back("different number of keys");
  return diffs;
}

}  // namespace seamless::config
