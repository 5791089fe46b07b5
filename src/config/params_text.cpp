#include "config/params_text.hpp"

#include <charconv>
#include <cstdio>

namespace seamless::config {
namespace {

// Shortest text that reads back to the same value (std::to_chars without precision), in fixed
// notation ("0.0005") when that is short, else in scientific ("1e+12").
template <class F> std::string shortest(F v) {
  char buf[400];  // fixed notation of a double can take ~310 digits
  auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  if (res.ec == std::errc() && res.ptr - buf <= 10) return std::string(buf, res.ptr);
  res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

bool is_plain_safe(const std::string& s) {
  if (s.empty() || s == "~" || s == "null" || s == "Null" || s == "NULL") return false;
  if (s.front() == '-' || s.front() == '.' || s.front() == ' ' || s.back() == ' ') return false;
  for (char ch : s) {
    bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' ||
              ch == '.' || ch == '/' || ch == '-' || ch == '+';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

std::string format_number(double v) { return shortest(v); }
std::string format_number(float v) { return shortest(v); }
std::string format_bool(bool v) { return v ? "true" : "false"; }

std::string format_string(const std::string& s) {
  if (is_plain_safe(s)) return s;
  std::string out = "\"";
  for (unsigned char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += static_cast<char>(ch);
    } else if (ch < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", ch);
      out += buf;
    } else {
      out += static_cast<char>(ch);
    }
  }
  return out + "\"";
}

std::string format_vec3(vec3 v) {
  std::string s = "[";  // appended step by step: GCC 12 warns falsely (-Wrestrict) on "[" + str
  s += format_number(v.x);
  s += ", ";
  s += format_number(v.y);
  s += ", ";
  s += format_number(v.z);
  return s + "]";
}

std::string constraint_text() { return ""; }
std::string constraint_text(const Range& r) { return " [" + format_number(r.lo) + ", " + format_number(r.hi) + "]"; }
std::string constraint_text(const Choices& c) {
  std::string s = " (";
  for (std::size_t i = 0; i < c.values.size(); ++i) s += (i ? " | " : "") + c.values[i];
  return s + ")";
}

}  // namespace seamless::config
