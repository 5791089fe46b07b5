#include "config/params_yaml.hpp"

#include <algorithm>
#include <cctype>

namespace seamless::config {
namespace {

std::string lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::string trim(const std::string& s) {
  auto b = s.find_first_not_of(" \t");
  auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string join(const std::vector<std::string>& parts, const std::string& sep, std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n && i < parts.size(); ++i) s += (i ? sep : "") + parts[i];
  return s;
}

// Optimal string alignment distance: Levenshtein plus adjacent transpositions ("voxle").
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// Covers: the error's key is the overridden key, inside it, or on the way to it.
bool covers(const std::string& override_path, const std::string& path) {
  auto prefix = [](const std::string& a, const std::string& b) {
    return b.size() > a.size() && b.compare(0, a.size(), a) == 0 && b[a.size()] == '.';
  };
  return path == override_path || prefix(override_path, path) || prefix(path, override_path);
}

bool parse_index(const std::string& s, std::size_t& out) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
         parse_number(s, out);
}

YAML::Node empty_container_for(const std::string& next_segment) {
  std::size_t idx;
  return YAML::Node(parse_index(next_segment, idx) ? YAML::NodeType::Sequence : YAML::NodeType::Map);
}

// Walks/creates segs[i..] below `node` and puts `value` at the end. Node handles are copied, never
// assigned, because assigning a yaml-cpp Node overwrites the node it refers to.
void set_in(YAML::Node node, const std::vector<std::string>& segs, std::size_t i, const YAML::Node& value,
            const std::string& option) {
  const std::string& seg = segs[i];
  const bool last = i + 1 == segs.size();
  const std::string parent = i == 0 ? "(top level)" : join(segs, ".", i);
  auto fail = [&](const std::string& what) { throw ConfigError("(from --set " + option + "): " + what); };
  if (node.IsSequence()) {
    std::size_t idx;
    if (!parse_index(seg, idx)) fail("'" + parent + "' is a list; address its entries by index, e.g. " + parent + ".0");
    if (idx > node.size())
      fail("'" + parent + "' has " + std::to_string(node.size()) + " entries; use an index from 0 to " +
           std::to_string(node.size()) + " (the last one appends)");
    if (idx == node.size()) node.push_back(last ? value : empty_container_for(segs[i + 1]));
    else if (last) node[idx] = value;
    if (last) return;
    YAML::Node child = node[idx];
    if (child.IsNull()) node[idx] = empty_container_for(segs[i + 1]);
    if (node[idx].IsScalar()) fail("'" + join(segs, ".", i + 1) + "' is a value, not a section or list");
    set_in(node[idx], segs, i + 1, value, option);
    return;
  }
  if (!node.IsMap()) fail("'" + parent + "' is a value, not a section");
  if (last) {
    node[seg] = value;
    return;
  }
  YAML::Node existing = node[seg];
  if (!existing.IsDefined() || existing.IsNull()) node[seg] = empty_container_for(segs[i + 1]);
  else if (existing.IsScalar()) fail("'" + join(segs, ".", i + 1) + "' is a value, not a section or list");
  set_in(node[seg], segs, i + 1, value, option);
}

}  // namespace

std::string join_path(const std::string& prefix, const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size());
  return "a section (map)";
}

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  // Allow about one typo per three letters, at least one, at most three: "dx" must not suggest
  // "dt" AND "nx" for everything, while "voxle_sise" still finds "voxel_size".
  const std::size_t budget = std::clamp<std::size_t>(word.size() / 3, 1, 3);
  std::string best;
  std::size_t best_d = budget + 1;
  for (const auto& c : candidates) {
    std::size_t d = edit_distance(lower(word), lower(c));
    if (d < best_d) best = c, best_d = d;
  }
  return best;
}

std::string nonfinite_name(const std::string& text) {
  std::string l = lower(trim(text));
  if (!l.empty() && (l[0] == '+' || l[0] == '-')) l.erase(0, 1);
  if (!l.empty() && l[0] == '.') l.erase(0, 1);
  if (l == "nan") return "NaN";
  if (l == "inf" || l == "infinity") return "infinity";
  return "";
}

std::string number_problem(const std::string& text, const std::string& expected) {
  const std::string what = nonfinite_name(text);
  if (!what.empty())
    return "expected " + expected + ", got " + what + " ('" + text + "'), which is not a finite number";
  return "expected " + expected + ", got '" + text + "'";
}

bool parse_bool(const std::string& s, bool& out) {
  std::string l = lower(s);
  if (l == "true" || l == "yes" || l == "on") return out = true, true;
  if (l == "false" || l == "no" || l == "off") return out = false, true;
  return false;
}

void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, double v, const Range& r) {
  if (v >= r.lo && v <= r.hi) return;
  ctx.error(n, path,
            "out of range: got " + describe(n) + ", expected a value in [" + format_number(r.lo) + ", " +
                format_number(r.hi) + "]");
}

void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, float v, const Range& r) {
  // Compared in float on purpose. (GCC 12 at -O2 drops a double->float->double round trip of the
  // bounds when they are passed through a helper, so the rounding must not rely on that.)
  const float lo = static_cast<float>(r.lo), hi = static_cast<float>(r.hi);
  if (v >= lo && v <= hi) return;
  ctx.error(n, path,
            "out of range: got " + describe(n) + ", expected a value in [" + format_number(r.lo) + ", " +
                format_number(r.hi) + "]");
}

void check_constraint(LoadContext& ctx, const YAML::Node& n, const std::string& path, const std::string& v,
                      const Choices& c) {
  if (std::find(c.values.begin(), c.values.end(), v) != c.values.end()) return;
  std::string what = "got '" + v + "', expected one of " + join(c.values, ", ", c.values.size());
  std::string guess = did_you_mean(v, c.values);
  if (!guess.empty()) what += "; did you mean '" + guess + "'?";
  ctx.error(n, path, what);
}

// ---- LoadContext ------------------------------------------------------------------------------

std::string LoadContext::where(const YAML::Node& at, const std::string& path) const {
  for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it)  // the last --set wins
    if (covers(it->path, path)) return "(from --set " + it->text + ")";
  YAML::Mark m = at.Mark();
  if (m.line < 0) return source_;
  return source_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

void LoadContext::error(const YAML::Node& at, const std::string& path, const std::string& what) {
  std::string at_where = where(at, path);
  long pos = at_where.rfind("(from --set", 0) == 0 || at.Mark().pos < 0 ? 1L << 40 : at.Mark().pos;
  errors_.push_back({pos, at_where + ": " + path + ": " + what});
  refused_.push_back(path);
}

bool LoadContext::names_refused_key(const std::string& message) const {
  for (const std::string& key : refused_) {
    for (std::size_t p = message.find(key); p != std::string::npos; p = message.find(key, p + 1)) {
      const std::size_t end = p + key.size();
      auto part_of_name = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
      if ((p == 0 || !part_of_name(message[p - 1])) && (end == message.size() || !part_of_name(message[end])))
        return true;
    }
  }
  return false;
}

void LoadContext::problem(const std::string& message) { errors_.push_back({1L << 40, message}); }

void LoadContext::unknown_key(const YAML::Node& key, const std::string& path, const std::vector<std::string>& known) {
  std::string name = path.substr(path.rfind('.') + 1);  // npos + 1 == 0
  std::string what = "unknown key '" + name + "'";
  std::string guess = did_you_mean(name, known);
  if (!guess.empty()) {
    what += "; did you mean '" + guess + "'?";
  } else {
    for (const auto& k : schema_) {
      auto dot = k.path.rfind('.');
      if (dot != std::string::npos && k.path.substr(dot + 1) == name) {
        what += "; '" + name + "' is a key of section '" + k.path.substr(0, dot) + "' (" + k.path + ")";
        break;
      }
    }
  }
  std::string section =
      path.size() > name.size() ? "'" + path.substr(0, path.size() - name.size() - 1) + "'" : "the top level";
  what += " (keys of " + section + ": " + join(known, ", ", known.size()) + ")";
  error(key, path, what);
}

void LoadContext::throw_if_errors() const {
  if (errors_.empty()) return;
  const char* hint = "\n(every key: `seamless config --list` or docs/CONFIG.md)";
  if (errors_.size() == 1) throw ConfigError(errors_[0].message + hint);
  auto sorted = errors_;
  std::stable_sort(sorted.begin(), sorted.end(), [](const Problem& a, const Problem& b) { return a.order < b.order; });
  std::string msg = std::to_string(errors_.size()) + " problems in the configuration:";
  for (const auto& e : sorted) msg += "\n  " + e.message;
  throw ConfigError(msg + hint);
}

// ---- SectionReader ----------------------------------------------------------------------------

SectionReader::SectionReader(LoadContext& ctx, const YAML::Node& map, std::string path)
    : ctx_(ctx), path_(std::move(path)) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    if (!it->first.IsScalar()) {
      ctx_.error(it->first, path_.empty() ? "(top level)" : path_,
                 "keys must be plain names, got " + describe(it->first));
      continue;
    }
    std::string name = it->first.Scalar();
    bool dup = std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
    if (dup) {
      ctx_.error(it->first, join_path(path_, name), "duplicate key (remove one: which one wins is not obvious)");
      continue;
    }
    entries_.push_back({name, it->first, it->second});
  }
}

void SectionReader::report_unknown() {
  for (auto& e : entries_)
    if (!e.used) ctx_.unknown_key(e.key, join_path(path_, e.name), known_);
}

// ---- overrides ----------------------------------------------------------------------------------

Override apply_override(YAML::Node& root, const std::string& assignment) {
  auto eq = assignment.find('=');
  std::string key = trim(assignment.substr(0, eq));
  if (eq == std::string::npos || key.empty())
    throw ConfigError("--set expects key.path=value (e.g. --set volume.voxel_size=0.01), got '" + assignment + "'");
  std::vector<std::string> segs;
  for (std::size_t b = 0;;) {
    auto dot = key.find('.', b);
    segs.push_back(key.substr(b, dot == std::string::npos ? std::string::npos : dot - b));
    if (segs.back().empty()) throw ConfigError("(from --set " + assignment + "): empty key segment in '" + key + "'");
    if (dot == std::string::npos) break;
    b = dot + 1;
  }
  std::string text = trim(assignment.substr(eq + 1));
  YAML::Node value = [&] {
    if (text.empty()) return YAML::Node(std::string());  // `--set input.path=` clears a string
    try {
      return YAML::Load(text);
    } catch (const YAML::Exception& e) {
      throw ConfigError("(from --set " + assignment + "): cannot parse '" + text + "' as a YAML value: " + e.msg);
    }
  }();
  if (!root.IsDefined() || root.IsNull()) root.reset(YAML::Node(YAML::NodeType::Map));
  set_in(root, segs, 0, value, assignment);
  return {key, assignment};
}

}  // namespace seamless::config
