// The YAML *reader* over parameter structs (core/params.hpp): loads a YAML tree into a struct,
// checking every key, type, range and choice, and reports every problem with the file position
// (or the --set option it came from), the full key path, what was expected and, for near misses,
// a "did you mean". Also: --set overrides applied to the YAML tree before validation.
// This header includes yaml-cpp; the yaml-free API for the app is config/config.hpp.
#pragma once
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "config/params_text.hpp"
#include "core/error.hpp"

namespace seamless::config {

struct Override {
  std::string path;  // normalised key path, "spawn.0.rate"
  std::string text;  // the option as given, "spawn.0.rate=3"
};

// Collects the problems found while loading one config; throws them all at once.
class LoadContext {
 public:
  explicit LoadContext(std::string source, std::vector<Override> overrides = {}, std::vector<KeyInfo> schema = {})
      : source_(std::move(source)), overrides_(std::move(overrides)), schema_(std::move(schema)) {}

  // Records "where: path: what" with where = file:line:column or (from --set ...).
  void error(const YAML::Node& at, const std::string& path, const std::string& what);
  void unknown_key(const YAML::Node& key, const std::string& path, const std::vector<std::string>& known);
  // Records a problem whose message says where it is already (a --set that cannot be applied).
  void problem(const std::string& message);
  bool ok() const { return errors_.empty(); }
  // A message (a rule across keys) names a key whose value error() refused: that key kept its
  // default, so the rule's verdict on it means nothing.
  bool names_refused_key(const std::string& message) const;
  // Throws seamless::ConfigError listing every problem (one per line) if there was any.
  void throw_if_errors() const;

 private:
  std::string where(const YAML::Node& at, const std::string& path) const;
  std::string source_;
  std::vector<Override> overrides_;
  std::vector<KeyInfo> schema_;  // for "'x' belongs in section 'y'" hints; may be empty
  struct Problem {
    long order;  // position in the file (overrides after the file), to report in reading order
    std::string message;
  };
  std::vector<Problem> errors_;
  std::vector<std::string> refused_;  // key paths error() reported
};

// Closest candidate within a small edit distance (optimal string alignment, case-insensitive),
// or "" when nothing is close enough to be a plausible typo.
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
// "'abc'", "a list", "a section", "nothing": what the user wrote, for error messages.
std::string describe(const YAML::Node& n);
std::string join_path(const std::string& prefix, const std::string& name);

// Parses "a.b.c=value" and sets that key in `root` (a YAML map, created if null). The value is
// parsed as YAML (so `[0,1,2]` and `[]` work); numeric segments index lists ("spawn.0.rate";
// index == size appends). Throws seamless::Error for malformed options.
Override apply_override(YAML::Node& root, const std::string& assignment);

// ---- reading leaves ---------------------------------------------------------------------------

bool parse_bool(const std::string& s, bool& out);

// "NaN" or "infinity" when `text` spells one (YAML's .nan and .inf, C's nan and inf, any case),
// "" otherwise: such a value is named for what it is, not as an unreadable number.
std::string nonfinite_name(const std::string& text);
// The message for a number that is not one: what was given and what is expected.
std::string number_problem(const std::string& text, const std::string& expected);

// A list of sections (spawn) holds at most this many entries (docs/CONFIG.md): each becomes
// particles, and a list of a million entries was read into gigabytes before anything told.
constexpr std::size_t kMaxSectionListEntries = 10000;

template <class T> bool parse_number(std::string s, T& out) {
  if (!s.empty() && s.front() == '+') s.erase(0, 1);
  auto res = std::from_chars(s.data(), s.data() + s.size(), out);
  return res.ec == std::errc() && res.ptr == s.data() + s.size() && !s.empty();
}

template <class T> std::string expected_text() {
  if constexpr (std::same_as<T, bool>) return "true or false";
  else if constexpr (Integer<T> && std::is_signed_v<T>) return "an integer (" + type_name<T>() + ")";
  else if constexpr (Integer<T>) return "a non-negative integer (" + type_name<T>() + ")";
  else if constexpr (std::floating_point<T>) return "a number (" + type_name<T>() + ")";
  else if constexpr (std::same_as<T, std::string> || NamedEnum<T>) return "a string";
  else return "a list of 3 numbers [x, y, z]";
}

inline void check_constraint(LoadContext&, const YAML::Node&, const std::string&, double) {}
inline void check_constraint(LoadContext&, const YAML::Node&, const std::string&, float) {}
inline void check_constraint(LoadContext&, const YAML::Node&, const std::string&, const std::string&) {}
void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, double v, const Range& r);
// A float field is compared with its bounds rounded to float: `0.1` must pass Range{0, 0.1}
// although float(0.1) > 0.1 as doubles.
void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, float v, const Range& r);
void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, const std::string& v,
                      const Choices& c);

template <class T>
bool read_scalar_text(LoadContext& ctx, const YAML::Node& n, const std::string& path, std::string& text) {
  if (n.IsScalar()) {
    text = n.Scalar();
    return true;
  }
  ctx.error(n, path, "expected " + expected_text<T>() + ", got " + describe(n));
  return false;
}

template <class T, class... C>
bool read_leaf(LoadContext& ctx, const YAML::Node& n, const std::string& path, T& out, const C&... c) {
  if constexpr (std::same_as<T, std::string>) {
    if (n.IsNull()) {
      out.clear();  // `path:` with nothing after it means the empty string
    } else if (!read_scalar_text<T>(ctx, n, path, out)) {
      return false;
    }
    check_constraint(ctx, n, path, out, c...);
    return true;
  } else if constexpr (NamedEnum<T>) {
    static_assert(sizeof...(C) == 0, "a named enum's allowed values come from its enum_names table");
    std::string text;  // `path:` with nothing after it is the empty string, which no table holds
    if (!n.IsNull() && !read_scalar_text<T>(ctx, n, path, text)) return false;
    if (enum_from_name(text, out)) return true;
    check_constraint(ctx, n, path, text, enum_choices<T>());  // reports the allowed names
    return false;
  } else if constexpr (std::same_as<T, vec3>) {
    float xyz[3];
    bool ok = n.IsSequence() && n.size() == 3;
    for (std::size_t i = 0; ok && i < 3; ++i) {
      ok = n[i].IsScalar() && parse_number(n[i].Scalar(), xyz[i]) && std::isfinite(xyz[i]);
      if (!ok && n[i].IsScalar()) {
        ctx.error(n, path,
                  "element " + std::to_string(i) + ": " + number_problem(n[i].Scalar(), expected_text<float>()));
        return false;
      }
    }
    if (!ok) {
      ctx.error(n, path, "expected " + expected_text<T>() + ", got " + describe(n));
      return false;
    }
    out = {xyz[0], xyz[1], xyz[2]};
    return true;
  } else {
    std::string text;
    if (!read_scalar_text<T>(ctx, n, path, text)) return false;
    bool ok;
    if constexpr (std::same_as<T, bool>) ok = parse_bool(text, out);
    else if constexpr (std::floating_point<T>) ok = parse_number(text, out) && std::isfinite(out);
    else ok = parse_number(text, out);
    if (!ok) {
      if constexpr (std::same_as<T, bool>)
        ctx.error(n, path, "expected " + expected_text<T>() + ", got " + describe(n));
      else ctx.error(n, path, number_problem(text, expected_text<T>()));
      return false;
    }
    if constexpr (std::same_as<T, float>) check_constraint(ctx, n, path, out, c...);
    else if constexpr (!std::same_as<T, bool>) check_constraint(ctx, n, path, static_cast<double>(out), c...);
    return true;
  }
}

// ---- reading sections -------------------------------------------------------------------------

template <class T, class... C>
void read_field(LoadContext& ctx, const YAML::Node& n, const std::string& path, T& out, const C&... c);

// The visitor: looks each declared key up in one YAML map; afterwards reports the keys nobody
// declared (unknown keys) and duplicates.
class SectionReader {
 public:
  SectionReader(LoadContext& ctx, const YAML::Node& map, std::string path);

  template <class T, class... C> void operator()(const char* name, T& field, const char*, const C&... c) {
    known_.emplace_back(name);
    for (auto& e : entries_) {
      if (e.name != name) continue;
      e.used = true;
      read_field(ctx_, e.value, join_path(path_, name), field, c...);
      return;
    }
  }
  void report_unknown();

 private:
  struct Entry {
    std::string name;
    YAML::Node key, value;
    bool used = false;
  };
  LoadContext& ctx_;
  std::string path_;
  std::vector<Entry> entries_;
  std::vector<std::string> known_;
};

template <class P> void read_section(LoadContext& ctx, const YAML::Node& n, const std::string& path, P& p) {
  if (!n || n.IsNull()) return;  // `section:` with nothing under it keeps the defaults
  if (!n.IsMap()) {
    ctx.error(n, path.empty() ? "(top level)" : path, "expected a section (a map of key: value), got " + describe(n));
    return;
  }
  SectionReader reader(ctx, n, path);
  p.visit(reader);
  reader.report_unknown();
}

template <class T, class... C>
void read_field(LoadContext& ctx, const YAML::Node& n, const std::string& path, T& out, const C&... c) {
  if constexpr (Visitable<T>) {
    read_section(ctx, n, path, out);
  } else if constexpr (SectionVector<T> || LeafVector<T>) {
    if (n.IsNull()) {
      out.clear();
      return;
    }
    if (!n.IsSequence()) {
      ctx.error(n, path,
                "expected a list ([...] or '- ' items) of " +
                    std::string(SectionVector<T> ? "sections" : type_name<typename VectorOf<T>::type>()) + ", got " +
                    describe(n));
      return;
    }
    if (SectionVector<T> && n.size() > kMaxSectionListEntries) {
      ctx.error(n, path,
                "a list of " + std::to_string(n.size()) + " entries; at most " +
                    std::to_string(kMaxSectionListEntries) + " entries are allowed (docs/CONFIG.md)");
      return;
    }
    T result;
    for (std::size_t i = 0; i < n.size(); ++i) {
      typename VectorOf<T>::type element{};
      std::string element_path = path + "." + std::to_string(i);
      if constexpr (SectionVector<T>) read_section(ctx, n[i], element_path, element);
      else read_leaf(ctx, n[i], element_path, element, c...);
      result.push_back(std::move(element));
    }
    out = std::move(result);
  } else {
    static_assert(Leaf<T>, "unsupported parameter field type (see core/params.hpp)");
    T value = out;
    if (read_leaf(ctx, n, path, value, c...)) out = value;
  }
}

// Loads `root` into a P that starts from its defaults; throws seamless::Error on any problem.
template <class P> P load_params(const YAML::Node& root, LoadContext& ctx) {
  P p{};
  read_section(ctx, root, "", p);
  ctx.throw_if_errors();
  return p;
}

}  // namespace seamless::config
