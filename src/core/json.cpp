#include "core/json.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "core/error.hpp"

namespace seamless {

std::string json_quote(std::string_view s) {
  std::string o;
  o.reserve(s.size() + 2);
  o += '"';
  for (char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\b': o += "\\b"; break;
      case '\f': o += "\\f"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (c < 0x20) {  // the other control characters have no short form (RFC 8259, section 7)
          char u[8];
          std::snprintf(u, sizeof u, "\\u%04x", c);
          o += u;
        } else {
          o += ch;
        }
    }
  }
  o += '"';
  return o;
}

void JsonWriter::newline() {
  if (indent_ <= 0) return;
  out_ += '\n';
  out_.append(stack_.size() * static_cast<std::size_t>(indent_), ' ');
}

void JsonWriter::before_value() {
  if (done_) throw std::logic_error("JsonWriter: a second top-level value");
  if (stack_.empty()) return;
  Level& l = stack_.back();
  if (l.object) {
    if (!l.key_pending) throw std::logic_error("JsonWriter: a value in an object without a key");
    l.key_pending = false;
    return;
  }
  if (!l.empty) out_ += ',';
  l.empty = false;
  newline();
}

JsonWriter& JsonWriter::key(std::string_view k) {
  if (stack_.empty() || !stack_.back().object || stack_.back().key_pending)
    throw std::logic_error("JsonWriter: a key outside an object or after another key");
  Level& l = stack_.back();
  if (!l.empty) out_ += ',';
  l.empty = false;
  l.key_pending = true;
  newline();
  out_ += json_quote(k);
  out_ += indent_ > 0 ? ": " : ":";
  return *this;
}

JsonWriter& JsonWriter::begin_object() {
  before_value();
  out_ += '{';
  stack_.push_back({true});
  return *this;
}

JsonWriter& JsonWriter::begin_array() {
  before_value();
  out_ += '[';
  stack_.push_back({false});
  return *this;
}

JsonWriter& JsonWriter::end_object() {
  if (stack_.empty() || !stack_.back().object || stack_.back().key_pending)
    throw std::logic_error("JsonWriter: end_object without an open object (or after a key)");
  const bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) newline();
  out_ += '}';
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::end_array() {
  if (stack_.empty() || stack_.back().object) throw std::logic_error("JsonWriter: end_array without an open array");
  const bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) newline();
  out_ += ']';
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view s) {
  before_value();
  out_ += json_quote(s);
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::value(double v) {
  if (!std::isfinite(v)) return null();  // JSON has no NaN or infinity
  before_value();
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest form that reads back as v
  out_.append(buf, r.ptr);
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::value(std::int64_t v) {
  before_value();
  out_ += std::to_string(v);
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::value(std::size_t v) {
  before_value();
  out_ += std::to_string(v);
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::value(bool v) {
  before_value();
  out_ += v ? "true" : "false";
  done_ = stack_.empty();
  return *this;
}

JsonWriter& JsonWriter::null() {
  before_value();
  out_ += "null";
  done_ = stack_.empty();
  return *this;
}

std::string JsonWriter::str() const {
  if (!stack_.empty() || !done_) throw std::logic_error("JsonWriter: the document is not complete");
  return out_ + '\n';
}

void JsonWriter::write_file(const std::string& path) const {
  const std::string text = str();
  std::ofstream f(path, std::ios::binary);
  f << text;
  f.close();
  if (!f) throw Error("cannot write JSON file '" + path + "'");
}

}  // namespace seamless
