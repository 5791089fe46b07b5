#include "app/json_file.hpp"

#include <fstream>

#include "core/error.hpp"

namespace seamless::app {

std::string json_text(const Json& doc) { return doc.dump(2, ' ', false, Json::error_handler_t::replace) + '\n'; }

void write_json_file(const std::string& path, const Json& doc) {
  const std::string text = json_text(doc);
  std::ofstream f(path, std::ios::binary);
  f << text;
  f.close();
  if (!f) throw Error("cannot write JSON file '" + path + "'");
}

}  // namespace seamless::app
