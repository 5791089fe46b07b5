// The JSON files seamless writes (src/app/json_file.hpp) against the text RFC 8259 prescribes:
// names that broke the former string concatenation (quotes, backslashes, newlines, control
// characters), members in the order they were added (the documented schemas' order), numbers
// that read back as the same double, and what JSON cannot hold (NaN, invalid UTF-8).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "app/json_file.hpp"
#include "core/error.hpp"

using namespace seamless;
using seamless::app::Json;

TEST(JsonFile, EscapesWhatRfc8259Requires) {
  const Json j = {{"name", "say \"hi\" C:\\runs\\a two\nlines\tand\r"}, {"bell", std::string("\x07 nul\0", 6)}};
  EXPECT_EQ(app::json_text(j),
            "{\n  \"name\": \"say \\\"hi\\\" C:\\\\runs\\\\a two\\nlines\\tand\\r\",\n"
            "  \"bell\": \"\\u0007 nul\\u0000\"\n}\n");
}

TEST(JsonFile, KeepsInsertionOrderAndIndentsOneMemberPerLine) {
  Json j;
  j["z"] = 1, j["a"] = Json::array({2, 3}), j["m"] = Json::object();
  EXPECT_EQ(app::json_text(j), "{\n  \"z\": 1,\n  \"a\": [\n    2,\n    3\n  ],\n  \"m\": {}\n}\n");
}

TEST(JsonFile, NumbersRoundTripAndNonFiniteBecomeNull) {
  const Json j = Json::array({0.1, 1e-9, 0.02f, std::nan(""), std::numeric_limits<double>::infinity(), std::int64_t{-7},
                              std::size_t{18446744073709551615ull}});
  // Shortest forms that read back as the same double (0.02f widened to double is not 0.02);
  // NaN and infinity have no JSON form.
  EXPECT_EQ(j.dump(), "[0.1,1e-09,0.019999999552965164,null,null,-7,18446744073709551615]");
  EXPECT_EQ(app::json_text(j),
            "[\n  0.1,\n  1e-09,\n  0.019999999552965164,\n  null,\n  null,\n  -7,\n"
            "  18446744073709551615\n]\n");
  EXPECT_EQ(Json::parse("[0.019999999552965164]")[0].get<double>(), static_cast<double>(0.02f));
}

TEST(JsonFile, InvalidUtf8IsReplacedNotFatal) {
  // A Latin-1 file name ("Nie\xdfner"): replaced by U+FFFD so the document stays valid UTF-8.
  const Json j = {{"path",
                   "Nie\xdf"
                   "ner"},
                  {"ok",
                   "Nie\xc3\x9f"
                   "ner"}};
  EXPECT_EQ(app::json_text(j), "{\n  \"path\": \"Nie\xef\xbf\xbdner\",\n  \"ok\": \"Nie\xc3\x9fner\"\n}\n");
}

TEST(JsonFile, WritesTheFileAndNamesItWhenItCannot) {
  const auto path = std::filesystem::temp_directory_path() / "seamless_json_file_test.json";
  app::write_json_file(path.string(), Json{{"a", "b"}});
  std::ifstream f(path);
  std::stringstream text;
  text << f.rdbuf();
  EXPECT_EQ(text.str(), "{\n  \"a\": \"b\"\n}\n");
  std::filesystem::remove(path);
  try {
    app::write_json_file("/nonexistent-folder/x.json", Json::object());
    FAIL() << "no error for an unwritable path";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/x.json"), std::string::npos) << e.what();
  }
}
