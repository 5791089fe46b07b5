// The visitors are generic: any struct with visit() loads, writes and lists, not only Experiment.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config/params_text.hpp"
#include "config/params_yaml.hpp"

namespace seamless {
namespace {

using ::testing::HasSubstr;

struct Inner {
  double d = 0.25;
  std::vector<std::string> tags{"a b", "c"};
  template <class V> void visit(V& v) {
    v("d", d, "a double");
    v("tags", tags, "strings", Choices{"a b", "c", "d,e"});
  }
};

struct Outer {
  float f = 0.05f;
  std::vector<vec3> points{{1, 2, 3}};
  Inner inner;
  std::vector<Inner> items;
  template <class V> void visit(V& v) {
    v("f", f, "bounded by a decimal that is not a float", Range{0.0, 0.1});
    v("points", points, "list of vec3");
    v("inner", inner, "nested");
    v("items", items, "list of sections");
  }
};

Outer load(const std::string& text) {
  config::LoadContext ctx("generic.yaml");
  return config::load_params<Outer>(YAML::Load(text), ctx);
}

std::string load_error(const std::string& text) {
  try {
    load(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigGeneric, FloatBoundsAreInclusiveAtFloatPrecision) {
  EXPECT_EQ(load("f: 0.1").f, 0.1f);  // float(0.1) > 0.1 as doubles; must still be accepted
  EXPECT_THAT(load_error("f: 0.1000001"), HasSubstr("generic.yaml:1:4: f: out of range"));
  EXPECT_THAT(load_error("f: -0.0000001"), HasSubstr("out of range"));
}

TEST(ConfigGeneric, VectorsOfVec3AndStringsWithChoices) {
  Outer o = load("points: [[0, 0, 1], [4, 5, 6]]\ninner: {tags: ['d,e', c]}\nitems: [{d: 2}, {}]\n");
  ASSERT_EQ(o.points.size(), 2u);
  EXPECT_EQ(o.points[1].y, 5.f);
  EXPECT_EQ(o.inner.tags, (std::vector<std::string>{"d,e", "c"}));
  ASSERT_EQ(o.items.size(), 2u);
  EXPECT_EQ(o.items[0].d, 2.0);
  EXPECT_EQ(o.items[1].tags, Inner{}.tags);  // `{}` entry: all defaults
  EXPECT_THAT(load_error("points: [[0, 0]]"), HasSubstr("points.0: expected a list of 3 numbers"));
  EXPECT_THAT(load_error("inner: {tags: [x]}"), HasSubstr("inner.tags.0: got 'x', expected one of a b, c, d,e"));
}

TEST(ConfigGeneric, WriteLoadRoundTripAndKeyList) {
  Outer o;
  o.f = 0.07f;
  o.items = {Inner{}, Inner{1.0 / 7.0, {"d,e"}}};
  std::string text = config::params_to_yaml(o);
  EXPECT_THAT(text, HasSubstr("tags: [\"a b\", c]"));  // quoted only where needed
  EXPECT_TRUE(config::diff_params(o, load(text)).empty()) << text;

  auto keys = config::list_keys<Outer>();
  std::vector<std::string> paths;
  for (const auto& k : keys) paths.push_back(k.path);
  EXPECT_EQ(paths, (std::vector<std::string>{"f", "points", "inner", "inner.d", "inner.tags", "items", "items[].d",
                                             "items[].tags"}));
  EXPECT_EQ(keys[0].type, "float");
  EXPECT_EQ(keys[0].constraint, "[0, 0.1]");
  EXPECT_EQ(keys[1].type, "list of vec3");
  EXPECT_EQ(keys[1].value, "[[1, 2, 3]]");
}

}  // namespace
}  // namespace seamless
