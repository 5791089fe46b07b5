// --set overrides: applied to the YAML tree before validation, so they get the same checks, and
// an error in one names the option instead of a file position.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "config/config.hpp"

namespace seamless {
namespace {

using ::testing::HasSubstr;

const char* kBase = R"(name: base
volume:
  voxel_size: 0.005
spawn:
  - kind: fluid_block
    rate: 10
)";

std::string override_error(const std::string& yaml, const std::vector<std::string>& overrides) {
  try {
    parse_experiment(yaml, overrides, "base.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigOverride, NestedKeyAppearsInTheEffectiveConfig) {
  Experiment e = parse_experiment(kBase, {"volume.voxel_size=0.01", "input.synthetic.frames=7"}, "base.yaml");
  EXPECT_EQ(e.volume.voxel_size, 0.01f);
  EXPECT_EQ(e.input.synthetic.frames, 7);  // section absent from the file: created
  std::string yaml = to_yaml(e);
  EXPECT_THAT(yaml, HasSubstr("\n  voxel_size: 0.01  # "));
  EXPECT_THAT(yaml, HasSubstr("\n    frames: 7  # "));
  EXPECT_TRUE(diff_experiments(parse_experiment(yaml, {}, "effective.yaml"), e).empty());
}

TEST(ConfigOverride, ValuesAreYamlFlowNodes) {
  Experiment e =
      parse_experiment(kBase, {"solver.gravity=[0,0,-9.81]", "tracker.iterations=[4, 2]", "name=a b"}, "base.yaml");
  EXPECT_EQ(e.solver.gravity.z, -9.81f);
  EXPECT_EQ(e.tracker.iterations, (std::vector<int>{4, 2}));
  EXPECT_EQ(e.name, "a b");
  EXPECT_TRUE(parse_experiment(kBase, {"spawn=[]"}, "base.yaml").spawn.empty());
  Experiment two = parse_experiment(kBase, {"spawn=[{kind: emitter, rate: 5}, {kind: rigid}]"}, "base.yaml");
  ASSERT_EQ(two.spawn.size(), 2u);
  EXPECT_EQ(two.spawn[0].rate, 5.f);
  EXPECT_EQ(two.spawn[1].kind, SpawnKind::rigid);
  EXPECT_EQ(parse_experiment(kBase, {"input.path="}, "base.yaml").input.path, "");
}

TEST(ConfigOverride, LaterOverridesWin) {
  Experiment e = parse_experiment(kBase, {"volume.voxel_size=0.01", "volume.voxel_size=0.008"}, "base.yaml");
  EXPECT_EQ(e.volume.voxel_size, 0.008f);  // (0.02 would break the truncation rule: 2 voxels)
}

TEST(ConfigOverride, ListElementsByIndex) {
  Experiment e = parse_experiment(kBase, {"spawn.0.rate=3", "spawn.1.kind=cloth", "spawn.1.nx=9"}, "base.yaml");
  ASSERT_EQ(e.spawn.size(), 2u);  // index == size appends an entry
  EXPECT_EQ(e.spawn[0].rate, 3.f);
  EXPECT_EQ(e.spawn[0].kind, SpawnKind::fluid_block);  // the rest of the entry comes from the file
  EXPECT_EQ(e.spawn[1].kind, SpawnKind::cloth);
  EXPECT_EQ(e.spawn[1].nx, 9);
  EXPECT_EQ(parse_experiment("", {"spawn.0.kind=rigid"}, "empty.yaml").spawn.at(0).kind, SpawnKind::rigid);
  EXPECT_THAT(override_error(kBase, {"spawn.5.rate=3"}), HasSubstr("'spawn' has 1 entries"));
  EXPECT_THAT(override_error(kBase, {"spawn.first.rate=3"}), HasSubstr("'spawn' is a list"));
}

TEST(ConfigOverride, UnknownKeyNamesTheOptionAndSuggests) {
  std::string msg = override_error(kBase, {"volume.voxel_sise=0.01"});
  EXPECT_THAT(msg, HasSubstr("(from --set volume.voxel_sise=0.01): volume.voxel_sise: unknown key"));
  EXPECT_THAT(msg, HasSubstr("did you mean 'voxel_size'?"));
  EXPECT_THAT(msg, ::testing::Not(HasSubstr("base.yaml:")));
}

TEST(ConfigOverride, BadValuesNameTheOption) {
  EXPECT_THAT(override_error(kBase, {"volume.voxel_size=big"}),
              HasSubstr("(from --set volume.voxel_size=big): volume.voxel_size: expected a number (float)"));
  EXPECT_THAT(override_error(kBase, {"volume.layout=dens"}), HasSubstr("(from --set volume.layout=dens)"));
  EXPECT_THAT(override_error(kBase, {"spawn.0.kind=goo"}), HasSubstr("(from --set spawn.0.kind=goo): spawn.0.kind"));
  // Whole-list override: errors inside it are still the option's.
  EXPECT_THAT(override_error(kBase, {"spawn=[{kind: rigid, sise: [1,1,1]}]"}),
              HasSubstr("(from --set spawn=[{kind: rigid, sise: [1,1,1]}]): spawn.0.sise: unknown key"));
  // A problem in the file is still reported at its position when overrides are present.
  EXPECT_THAT(override_error("volume: {layot: hash}\n", {"volume.voxel_size=0.01"}),
              HasSubstr("base.yaml:1:10: volume.layot"));
}

TEST(ConfigOverride, MalformedOptions) {
  EXPECT_THAT(override_error(kBase, {"volume.voxel_size"}), HasSubstr("--set expects key.path=value"));
  EXPECT_THAT(override_error(kBase, {"=3"}), HasSubstr("--set expects key.path=value"));
  EXPECT_THAT(override_error(kBase, {"volume..voxel_size=1"}), HasSubstr("empty key segment"));
  EXPECT_THAT(override_error(kBase, {"name.first=x"}), HasSubstr("'name' is a value"));
  EXPECT_THAT(override_error(kBase, {"solver.gravity=[0,1"}), HasSubstr("cannot parse"));
}

// An option that cannot be applied at all (malformed, or a path through a value) was
// thrown on its own and hid every problem of the file; now they are all listed together, and the
// error is a ConfigError (exit code 4).
TEST(ConfigOverride, UnusableOptionIsListedWithTheFilesProblems) {
  const char* bad_file = "name: x\nvolume:\n  voxel_sise: 0.01\n  layout: dens\ntracker:\n  kindd: icp\n";
  std::string msg;
  try {
    parse_experiment(bad_file, {"name.first=x", "volume.voxel_size", "solver.dt=fast"}, "bad.yaml");
  } catch (const ConfigError& e) {
    msg = e.what();
  }
  EXPECT_THAT(msg, HasSubstr("6 problems in the configuration"));
  EXPECT_THAT(msg, HasSubstr("bad.yaml:3:3: volume.voxel_sise: unknown key"));
  EXPECT_THAT(msg, HasSubstr("bad.yaml:4:11: volume.layout"));
  EXPECT_THAT(msg, HasSubstr("bad.yaml:6:3: tracker.kindd: unknown key"));
  EXPECT_THAT(msg, HasSubstr("(from --set name.first=x): 'name' is a value"));
  EXPECT_THAT(msg,
              HasSubstr("--set expects key.path=value (e.g. --set volume.voxel_size=0.01), got 'volume.voxel_size'"));
  EXPECT_THAT(msg, HasSubstr("(from --set solver.dt=fast): solver.dt: expected a number"));
}

}  // namespace
}  // namespace seamless
