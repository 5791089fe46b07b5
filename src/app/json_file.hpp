// The JSON documents seamless writes (eval --json, bench --json, summary.json) are built as
// nlohmann::ordered_json (Debian's nlohmann-json3-dev): strings are escaped as RFC 8259 section 7
// requires, members keep the order they were added in (the documented schemas list them so), and
// numbers print in their shortest round-trip form. Kept out of the installed headers: a project
// using seamless's libraries does not need nlohmann.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace seamless::app {

using Json = nlohmann::ordered_json;

// `doc` indented by two spaces with a final newline. NaN and infinities (which JSON cannot hold)
// print as null; bytes that are not UTF-8 (a file name from another locale) become U+FFFD rather
// than making the whole document invalid.
std::string json_text(const Json& doc);
// json_text(doc) into `path`; throws seamless::Error naming the file when it cannot be written.
void write_json_file(const std::string& path, const Json& doc);

}  // namespace seamless::app
