// Config choices are enums with name tables (core/params.hpp): every enum field of the experiment
// must load each of its names back to the same value, write it back under the same name, and reject
// any other name with an error that names the key and lists the allowed names.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>

#include "config/config.hpp"
#include "config/params_yaml.hpp"

namespace seamless {
namespace {

using ::testing::HasSubstr;

// One enum field as a section of its own, so that each name is checked without the cross-field
// rules of the experiment (Experiment::validate) getting in the way.
template <class E> struct Holder {
  E value{};
  template <class V> void visit(V& v) { v("value", value, "the choice"); }
};

template <class E> Holder<E> load_holder(const std::string& yaml) {
  config::LoadContext ctx("holder.yaml");
  return config::load_params<Holder<E>>(YAML::Load(yaml), ctx);
}

std::string joined(const Choices& c, const char* sep) {
  std::string s;
  for (std::size_t i = 0; i < c.values.size(); ++i) s += (i ? sep : "") + c.values[i];
  return s;
}

template <class E> void check_enum(const std::string& path) {
  SCOPED_TRACE(path);
  const Choices allowed = enum_choices<E>();
  ASSERT_GE(allowed.values.size(), 2u) << "a choice of one is no choice";
  EXPECT_EQ(std::set<std::string>(allowed.values.begin(), allowed.values.end()).size(), allowed.values.size())
      << "names must be distinct";
  std::set<E> values;
  for (const std::string& name : allowed.values) {
    E e{};
    ASSERT_TRUE(enum_from_name(name, e)) << name;
    values.insert(e);
    EXPECT_EQ(enum_name(e), name);
    const Holder<E> h = load_holder<E>("value: " + name);
    EXPECT_EQ(h.value, e) << name;
    const std::string yaml = config::params_to_yaml(h);
    EXPECT_THAT(yaml, HasSubstr("value: " + name + "  # the choice (" + joined(allowed, " | ") + ")"));
    EXPECT_EQ(load_holder<E>(yaml).value, e) << yaml;
  }
  EXPECT_EQ(values.size(), allowed.values.size()) << "two names for one value";
  for (const std::string bad : {"not_a_choice", ""}) {
    try {
      load_holder<E>("value: " + bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const ConfigError& err) {
      EXPECT_THAT(std::string(err.what()),
                  HasSubstr("value: got '" + bad + "', expected one of " + joined(allowed, ", ")));
    }
  }
}

// Walks the experiment's sections (list elements through a default element) and checks every enum
// field it meets; records their paths.
struct EnumWalker {
  std::string prefix;
  std::vector<std::string>* found;
  template <class T, class... C> void operator()(const char* name, T& field, const char*, const C&...) {
    const std::string path = prefix.empty() ? name : prefix + "." + name;
    if constexpr (config::Visitable<T>) {
      EnumWalker nested{path, found};
      field.visit(nested);
    } else if constexpr (config::SectionVector<T>) {
      typename config::VectorOf<T>::type element{};
      EnumWalker nested{path + "[]", found};
      element.visit(nested);
    } else if constexpr (NamedEnum<T>) {
      found->push_back(path);
      check_enum<T>(path);
    }
  }
};

TEST(ConfigEnums, EveryEnumFieldRoundTripsItsNamesAndRejectsOthers) {
  std::vector<std::string> found;
  Experiment e;
  EnumWalker walker{"", &found};
  e.visit(walker);
  // The enums made so far; a new one is checked here without being listed.
  for (const char* path : {"mode",
                           "input.source",
                           "input.association",
                           "input.synthetic.trajectory",
                           "input.synthetic.movers[].kind",
                           "volume.layout",
                           "tracker.mode",
                           "tracker.photometric_reference",
                           "tracker.gravity",
                           "tracker.weighting",
                           "tracker.depth_noise",
                           "tracker.photometric_pixels",
                           "refine.keyframes",
                           "refine.pair_tracker",
                           "refine.weighting",
                           "refine.depth_noise",
                           "refine.photometric_pixels",
                           "refine.robust_loss",
                           "solver.scene_collision",
                           "solver.dynamic_colliders",
                           "spawn[].kind",
                           "spawn[].shape",
                           "spawn[].place.on",
                           "render.mode",
                           "render.view",
                           "render.camera",
                           "render.fluid",
                           "render.fluid_filter",
                           "render.fluid_splat"})
    EXPECT_NE(std::find(found.begin(), found.end(), path), found.end()) << path;
}

TEST(ConfigEnums, KeyListShowsTheAllowedNames) {
  for (const config::KeyInfo& k : experiment_keys())
    if (k.path == "volume.layout") {
      EXPECT_EQ(k.type, "string");
      EXPECT_EQ(k.value, "hash");
      EXPECT_EQ(k.constraint, "(hash | dense)");
      return;
    }
  ADD_FAILURE() << "volume.layout is not in the key list";
}

TEST(ConfigEnums, BadNameInAnExperimentNamesFileLineKeyAndChoices) {
  try {
    parse_experiment("render:\n  fluid_splat: rastr\n", {}, "exp.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& err) {
    EXPECT_THAT(std::string(err.what()),
                HasSubstr("exp.yaml:2:16: render.fluid_splat: got 'rastr', expected one of compute, raster; "
                          "did you mean 'raster'?"));
  }
}

}  // namespace
}  // namespace seamless
