// The effective config (every key, defaults included) must load back to exactly the same
// experiment: runs are reproduced from it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "config/config.hpp"

namespace seamless {
namespace {

using ::testing::HasSubstr;

// An experiment far from the defaults, with values that are hard to print exactly: floats that
// are not short decimals, extreme integers, strings that need quoting, lists of sections.
Experiment unusual_experiment() {
  Experiment e;
  e.name = "run: #1 \"quoted\" \\ back";
  e.device = "cpu";
  e.mode = ExperimentMode::scan_then_simulate;
  e.frames = 999999999999;  // the largest the range allows; not exact in a float or 32 bits
  e.input.path = "/data/with space/rgbd";
  e.input.synthetic.seed = std::numeric_limits<std::uint64_t>::max();
  e.input.depth_scale = 1000.0 / 3.0;
  e.volume.voxel_size = std::nextafter(0.005f, 1.f);  // one ulp off a short decimal
  e.volume.truncation = 0.0123456789f;
  e.volume.dense_origin = {-0.f, 1e-7f, -123.456f};
  e.tracker.iterations = {};
  e.solver.gravity = {0.1f, 0.2f, 0.3f};
  e.render.mode = RenderMode::none;
  e.output.dir = "";
  SpawnParams cloth;
  cloth.kind = SpawnKind::cloth;
  cloth.pinned = {0, 1, 2, 3};
  cloth.time = 0.1f;
  SpawnParams rigid;
  rigid.kind = SpawnKind::rigid;
  rigid.shape = RigidShape::mesh;
  rigid.mesh = "null";  // would read back as "nothing" if written plain
  e.spawn = {cloth, rigid};
  return e;
}

TEST(ConfigRoundTrip, DiffDetectsOneUlp) {
  // Guards the round-trip tests below against a comparison that sees no difference.
  Experiment a, b;
  b.solver.dt = std::nextafter(a.solver.dt, 1.f);
  auto d = diff_experiments(a, b);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_THAT(d[0], HasSubstr("solver.dt"));
  b = a;
  b.spawn.resize(1);
  EXPECT_FALSE(diff_experiments(a, b).empty());
}

TEST(ConfigRoundTrip, DefaultsWriteAndLoadBackIdentically) {
  Experiment e;
  Experiment back = parse_experiment(to_yaml(e), {}, "effective.yaml");
  EXPECT_TRUE(diff_experiments(e, back).empty()) << ::testing::PrintToString(diff_experiments(e, back));
}

TEST(ConfigRoundTrip, UnusualValuesThroughAFile) {
  Experiment e = unusual_experiment();
  auto dir = std::filesystem::path(::testing::TempDir()) / "seamless_config_roundtrip" / "run1";
  std::filesystem::remove_all(dir);
  std::string file = write_effective_config(e, dir.string() + "/");  // folder: creates it, writes config.yaml
  EXPECT_EQ(std::filesystem::path(file).filename(), "config.yaml");
  Experiment back = load_experiment(file);
  auto d = diff_experiments(e, back);
  EXPECT_TRUE(d.empty()) << ::testing::PrintToString(d);
  EXPECT_EQ(back.name, e.name);
  EXPECT_EQ(back.spawn.at(1).mesh, "null");
  // Writing the loaded copy gives the same text: the format is a fixed point.
  EXPECT_EQ(to_yaml(back), to_yaml(e));
}

TEST(ConfigRoundTrip, EffectiveConfigListsEveryKeyWithItsDoc) {
  Experiment e;
  e.spawn.resize(1);                   // so the spawn entry keys are written too
  e.input.synthetic.movers.resize(1);  // and the movers'
  std::string yaml = to_yaml(e);
  for (const auto& k : experiment_keys()) {
    std::string leaf = k.path.substr(k.path.rfind('.') + 1);  // npos + 1 == 0
    if (leaf.ends_with("[]")) leaf.resize(leaf.size() - 2);
    EXPECT_THAT(yaml, HasSubstr(leaf + ":")) << k.path;
    EXPECT_THAT(yaml, HasSubstr("# " + k.doc)) << k.path;
  }
  EXPECT_THAT(yaml, HasSubstr("layout: hash  # volume layout: voxel hashing or dense grid (hash | dense)"));
}

TEST(ConfigRoundTrip, OverriddenLoadWritesTheOverride) {
  auto dir = std::filesystem::path(::testing::TempDir()) / "seamless_config_roundtrip" / "run2";
  std::filesystem::create_directories(dir);
  Experiment e = parse_experiment("name: r\n", {"render.width=320", "spawn=[{kind: emitter}]"}, "r.yaml");
  std::string file = write_effective_config(e, (dir / "effective.yaml").string());
  Experiment back = load_experiment(file);
  EXPECT_EQ(back.render.width, 320);
  ASSERT_EQ(back.spawn.size(), 1u);
  EXPECT_EQ(back.spawn[0].kind, SpawnKind::emitter);
  EXPECT_TRUE(diff_experiments(e, back).empty());
}

TEST(ConfigRoundTrip, UnwritableTargetIsAClearError) {
  EXPECT_THROW(write_effective_config(Experiment{}, "/proc/seamless_cannot_write_here/config.yaml"), Error);
}

}  // namespace
}  // namespace seamless
