// A small JSON writer for the files seamless writes (eval, bench): every string escaped as RFC 8259
// section 7 requires, numbers in their shortest round-trip form, NaN and infinities (which JSON
// cannot hold) as null. Building JSON by string concatenation broke on names holding quotes,
// backslashes or newlines; everything goes through here instead.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace seamless {

// `s` as a JSON string literal, quotes included: " \ and control characters escaped (\n, \t,
// ..., \u00XX for the rest); other bytes (UTF-8 included) pass through unchanged.
std::string json_quote(std::string_view s);

// Writes one JSON document: containers open and close explicitly, commas and indentation are the
// writer's business. Misuse (a value without a key inside an object, an unclosed container at
// str()) throws std::logic_error: a bug in the caller, not user input.
class JsonWriter {
 public:
  explicit JsonWriter(int indent = 2) : indent_(indent) {}

  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(std::string_view k);

  JsonWriter& value(std::string_view s);
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
  JsonWriter& value(double v);
  JsonWriter& value(float v) { return value(static_cast<double>(v)); }
  JsonWriter& value(std::int64_t v);
  JsonWriter& value(int v) { return value(static_cast<std::int64_t>(v)); }
  JsonWriter& value(std::size_t v);
  JsonWriter& value(bool v);
  JsonWriter& null();

  // key(k).value(v)
  template <class T>
  JsonWriter& field(std::string_view k, const T& v) {
    return key(k).value(v);
  }

  // The document, with a final newline; every container must be closed.
  std::string str() const;
  // str() into `path`; throws seamless::Error naming the file when it cannot be written.
  void write_file(const std::string& path) const;

 private:
  void before_value();
  void newline();
  struct Level {
    bool object, empty = true, key_pending = false;
  };
  std::string out_;
  std::vector<Level> stack_;
  int indent_;
  bool done_ = false;
};

}  // namespace seamless
