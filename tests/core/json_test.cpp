// JsonWriter against the JSON text RFC 8259 prescribes, for names that broke the string
// concatenation it replaces (quotes, backslashes, newlines, control characters).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/json.hpp"

using namespace seamless;

TEST(Json, QuotesEscapeWhatRfc8259Requires) {
  EXPECT_EQ(json_quote("plain"), "\"plain\"");
  EXPECT_EQ(json_quote("say \"hi\""), "\"say \\\"hi\\\"\"");
  EXPECT_EQ(json_quote("C:\\runs\\a"), "\"C:\\\\runs\\\\a\"");
  EXPECT_EQ(json_quote("two\nlines\tand\r"), "\"two\\nlines\\tand\\r\"");
  EXPECT_EQ(json_quote(std::string("bell\x07 nul", 9) + '\0'), "\"bell\\u0007 nul\\u0000\"");
  EXPECT_EQ(json_quote("Nie\xc3\x9f" "ner"), "\"Nie\xc3\x9f" "ner\"");  // UTF-8 passes through
}

TEST(Json, WritesNestedDocumentsWithEscapedKeysAndValues) {
  JsonWriter w(0);  // compact, so that the whole text can be compared
  w.begin_object()
      .field("name", "fluid \"1m\"\n")
      .field("n", 3)
      .field("ok", true)
      .key("cases")
      .begin_array()
      .begin_object()
      .field("dir\\x", 0.5)
      .end_object()
      .value("a")
      .null()
      .end_array()
      .key("empty")
      .begin_object()
      .end_object()
      .end_object();
  EXPECT_EQ(w.str(),
            "{\"name\":\"fluid \\\"1m\\\"\\n\",\"n\":3,\"ok\":true,\"cases\":[{\"dir\\\\x\":0.5},\"a\",null],"
            "\"empty\":{}}\n");
}

TEST(Json, IndentsOneMemberPerLine) {
  JsonWriter w;
  w.begin_object().field("a", 1).key("b").begin_array().value(2).value(3).end_array().end_object();
  EXPECT_EQ(w.str(), "{\n  \"a\": 1,\n  \"b\": [\n    2,\n    3\n  ]\n}\n");
}

TEST(Json, NumbersRoundTripAndNonFiniteBecomeNull) {
  JsonWriter w(0);
  w.begin_array().value(0.1).value(1e-9).value(123456789.0).value(std::nan("")).value(
      std::numeric_limits<double>::infinity());
  w.value(std::int64_t{-7}).value(std::size_t{18446744073709551615ull}).end_array();
  // to_chars' shortest form: 0.1 reads back as the same double; NaN and inf have no JSON form.
  EXPECT_EQ(w.str(), "[0.1,1e-09,123456789,null,null,-7,18446744073709551615]\n");
}

TEST(Json, MisuseIsCaught) {
  JsonWriter a;
  a.begin_object();
  EXPECT_THROW(a.value(1), std::logic_error);  // no key
  EXPECT_THROW(a.str(), std::logic_error);     // not closed
  JsonWriter b;
  b.begin_array();
  EXPECT_THROW(b.key("k"), std::logic_error);
  EXPECT_THROW(b.end_object(), std::logic_error);
}
