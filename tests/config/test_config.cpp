// Loading and validation: every kind of bad input must name the file position, the full key
// path, what was expected, and (for near misses) suggest the intended word.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include <filesystem>
#include <fstream>

#include "config/config.hpp"
#include "config/params_yaml.hpp"
#include "seamless/build_config.hpp"

namespace seamless {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The message of the seamless::Error thrown by parsing `yaml`, or "" if nothing was thrown.
std::string error_of(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  try {
    parse_experiment(yaml, overrides, "test.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ConfigLoad, EmptyFileGivesDefaults) {
  Experiment e = parse_experiment("", {}, "empty.yaml");
  EXPECT_TRUE(diff_experiments(e, Experiment{}).empty());
}

TEST(ConfigLoad, MissingKeysKeepTheirDefaults) {
  Experiment e = parse_experiment("volume:\n  voxel_size: 0.01\noutput:\n", {}, "t.yaml");
  EXPECT_EQ(e.volume.voxel_size, 0.01f);
  EXPECT_EQ(e.volume.truncation, VolumeParams{}.truncation);
  EXPECT_EQ(e.output.dir, OutputParams{}.dir);  // `output:` with nothing under it = defaults
  EXPECT_EQ(e.tracker.iterations, (std::vector<int>{10, 5, 4}));
}

TEST(ConfigLoad, ReadsEveryFieldType) {
  Experiment e = parse_experiment(R"(
name: "my run: 2"
frames: 12345678901
input:
  synthetic: {seed: 18446744073709551615, noise: off}
  depth_scale: 1000.5
volume: {integrate_color: false}
tracker: {iterations: [3, 2], fixed_gravity: [0, -1, 0.5]}
spawn:
  - {kind: cloth, pinned: [0, 3], nx: 5}
  - kind: rigid
    position: [1, 2, 3]
)",
                                  {}, "t.yaml");
  EXPECT_EQ(e.name, "my run: 2");
  EXPECT_EQ(e.frames, 12345678901LL);
  EXPECT_EQ(e.input.synthetic.seed, 18446744073709551615ULL);
  EXPECT_FALSE(e.input.synthetic.noise);
  EXPECT_EQ(e.input.depth_scale, 1000.5);
  EXPECT_FALSE(e.volume.integrate_color);
  EXPECT_EQ(e.tracker.iterations, (std::vector<int>{3, 2}));
  EXPECT_EQ(e.tracker.fixed_gravity.z, 0.5f);
  ASSERT_EQ(e.spawn.size(), 2u);
  EXPECT_EQ(e.spawn[0].kind, SpawnKind::cloth);
  EXPECT_EQ(e.spawn[0].pinned, (std::vector<int>{0, 3}));
  EXPECT_EQ(e.spawn[0].nx, 5);
  EXPECT_EQ(e.spawn[1].kind, SpawnKind::rigid);
  EXPECT_EQ(e.spawn[1].position.y, 2.f);
  EXPECT_EQ(e.spawn[1].size.x, SpawnParams{}.size.x);  // element defaults apply per entry
}

TEST(ConfigErrors, MisspeltKeyGivesPositionPathAndSuggestion) {
  std::string msg = error_of("name: x\nvolume:\n  voxel_sise: 0.01\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:3:3:"));  // 1-based line and column of the key
  EXPECT_THAT(msg, HasSubstr("volume.voxel_sise"));
  EXPECT_THAT(msg, HasSubstr("did you mean 'voxel_size'?"));
  EXPECT_THAT(msg, HasSubstr("keys of 'volume':"));  // what was expected
}

TEST(ConfigErrors, TranspositionAndCaseAreNearMisses) {
  EXPECT_THAT(error_of("volume:\n  voxle_size: 1\n"), HasSubstr("did you mean 'voxel_size'?"));
  EXPECT_THAT(error_of("Volume:\n  voxel_size: 0.01\n"), HasSubstr("did you mean 'volume'?"));
}

TEST(ConfigErrors, FarOffKeyGetsNoSuggestionButTheKeyList) {
  std::string msg = error_of("tracker:\n  banana: 1\n");
  EXPECT_THAT(msg, HasSubstr("tracker.banana"));
  EXPECT_THAT(msg, ::testing::Not(HasSubstr("did you mean")));
  EXPECT_THAT(msg, HasSubstr("dist_threshold"));
}

TEST(ConfigErrors, KeyInTheWrongSectionNamesTheRightOne) {
  std::string msg = error_of("voxel_size: 0.01\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:1:1:"));
  EXPECT_THAT(msg, HasSubstr("volume.voxel_size"));
}

TEST(ConfigErrors, WrongType) {
  std::string msg = error_of("volume:\n  voxel_size: abc\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:2:15:"));  // position of the value
  EXPECT_THAT(msg, HasSubstr("volume.voxel_size"));
  EXPECT_THAT(msg, HasSubstr("expected a number (float), got 'abc'"));

  EXPECT_THAT(error_of("volume: {integrate_color: 3}"), HasSubstr("expected true or false, got '3'"));
  EXPECT_THAT(error_of("solver: {iterations: 1.5}"), HasSubstr("expected an integer (int), got '1.5'"));
  EXPECT_THAT(error_of("solver: {gravity: [0, -9.81]}"),
              HasSubstr("solver.gravity: expected a list of 3 numbers [x, y, z], got a list of 2"));
  EXPECT_THAT(error_of("volume: 3"), HasSubstr("volume: expected a section"));
  EXPECT_THAT(error_of("spawn: {kind: rigid}"), HasSubstr("spawn: expected a list"));
  EXPECT_THAT(error_of("input: {synthetic: {seed: -1}}"), HasSubstr("non-negative integer"));
  EXPECT_THAT(error_of("solver: {dt: .nan}"), HasSubstr("solver.dt: expected a number"));
}

TEST(ConfigErrors, OutOfRange) {
  std::string msg = error_of("volume:\n  voxel_size: 5\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:2:15:"));
  EXPECT_THAT(msg, HasSubstr("volume.voxel_size: out of range: got '5', expected a value in [0.0005, 1]"));
  // Ranges apply to each element of a list, and the element's index is part of the path.
  EXPECT_THAT(error_of("tracker: {iterations: [10, -1]}"), HasSubstr("tracker.iterations.1: out of range"));
}

TEST(ConfigErrors, BadChoice) {
  std::string msg = error_of("volume:\n  layout: hsah\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:2:11:"));
  EXPECT_THAT(msg, HasSubstr("volume.layout: got 'hsah', expected one of hash, dense; did you mean 'hash'?"));
}

TEST(ConfigErrors, RulesAcrossKeysAreCheckedAtLoad) {
  // Experiment::validate: combinations no single key's range can catch, as config errors before
  // anything runs (each names the keys involved).
  EXPECT_THAT(error_of("volume: {voxel_size: 0.01, truncation: 0.015}"),
              HasSubstr("volume.truncation (0.015000 m) must be at least two voxels"));
  EXPECT_EQ(error_of("volume: {voxel_size: 0.01, truncation: 0.02}"), "");  // exactly two voxels
  EXPECT_THAT(error_of("mode: scan_then_simulate\nsolver: {dynamic_colliders: all}"),
              HasSubstr("solver.dynamic_colliders: all needs mode: live"));
  EXPECT_EQ(error_of("mode: live\nsolver: {dynamic_colliders: all}"), "");
  // depth without dynamic.enabled is allowed (no pixel is dynamic, so nothing collides: the live
  // loop says so), so that `--set dynamic.enabled=false` compares a run with and without.
  EXPECT_EQ(error_of("mode: live\nsolver: {dynamic_colliders: depth}"), "");
  // support_plane: one height, and only where the floor plane is set up (after the scan).
  EXPECT_THAT(error_of("mode: scan_then_simulate\nsupport_plane: [-0.1, 0.2]"),
              HasSubstr("support_plane: expected [height] (one number) or [], got 2 numbers"));
  EXPECT_THAT(error_of("mode: live\nsupport_plane: [-0.1]"), HasSubstr("support_plane needs mode: scan_then_simulate"));
  EXPECT_EQ(error_of("mode: scan_then_simulate\nsupport_plane: [-0.1]"), "");
}

// Key errors and the rules across keys in one list: one run shows every problem of a file. A
// rule on a key whose value was refused (it kept its default) is left out: it would only confuse.
TEST(ConfigErrors, EveryProblemOfAFileAtOnce) {
  const std::string msg = error_of(
      "volume: {voxel_size: 0.01, truncation: 0.015, layout: hsah}\n"
      "render: {eye: [0, 1]}\n"
      "solver: {gravity: [0, -1e30, 0]}\n"
      "spawn:\n  - {kind: fluid_block, size: [-0.2, 0.2, 0.2]}\n"
      "tracker: {iterations: []}\n");
  EXPECT_THAT(msg, HasSubstr("6 problems in the configuration"));
  EXPECT_THAT(msg, HasSubstr("test.yaml:1:55: volume.layout: got 'hsah'"));
  EXPECT_THAT(msg, HasSubstr("volume.truncation (0.015000 m) must be at least two voxels"));
  EXPECT_THAT(msg, HasSubstr("render.eye: expected [x, y, z]"));
  EXPECT_THAT(msg, HasSubstr("solver.gravity: [0, -1e+30, 0] (|g| = 1e+30 m/s^2) is beyond the sanity bound of 100"));
  EXPECT_THAT(msg, HasSubstr("spawn.0.size: every extent must be positive (metres), got [-0.2, 0.2, 0.2]"));
  EXPECT_THAT(msg, HasSubstr("tracker.iterations: empty"));
  // voxel_size refused: the truncation rule, which would compare against the default, is left out.
  const std::string refused = error_of("volume: {voxel_size: big, truncation: 0.001}");
  EXPECT_THAT(refused, HasSubstr("volume.voxel_size: expected a number"));
  EXPECT_THAT(refused, Not(HasSubstr("two voxels")));
}

// Values that parse but mean nothing physically, refused at load with the key and the value.
TEST(ConfigErrors, PhysicalSanity) {
  EXPECT_EQ(error_of("solver: {gravity: [0, -9.81, 0]}"), "");
  EXPECT_EQ(error_of("solver: {gravity: [0, 0, 0]}"), "");     // no gravity: a valid experiment
  EXPECT_EQ(error_of("solver: {gravity: [0, -100, 0]}"), "");  // the bound itself
  EXPECT_THAT(error_of("solver: {gravity: [0, -101, 0]}"), HasSubstr("beyond the sanity bound of 100 m/s^2"));
  EXPECT_THAT(error_of("spawn: [{kind: rigid, size: [0, 0, 0]}]"),
              HasSubstr("spawn.0.size: every extent must be positive"));
  EXPECT_EQ(error_of("spawn: [{kind: cloth, size: [0, 0, 0]}]"), "");  // cloth's extent is nx, ny and spacing
  EXPECT_THAT(error_of("tracker: {iterations: [0, 0, 0]}"), HasSubstr("tracker.iterations: no level has an iteration"));
  EXPECT_EQ(error_of("tracker: {iterations: [0, 5, 4]}"), "");               // skipping the finest level is a choice
  EXPECT_EQ(error_of("tracker: {kind: ground_truth, iterations: []}"), "");  // it does not iterate
  EXPECT_THAT(error_of("input: {intrinsics: {preset: custom, fx: 0}}"),
              HasSubstr("input.intrinsics.fx and fy must not be 0"));
}

// NaN and infinity are named as such, in numbers and in vectors (YAML's .nan and .inf).
TEST(ConfigErrors, NanIsNamedNan) {
  EXPECT_THAT(error_of("solver: {dt: .nan}"), HasSubstr("solver.dt: expected a number (float), got NaN ('.nan')"));
  EXPECT_THAT(error_of("solver: {dt: -.inf}"), HasSubstr("got infinity ('-.inf')"));
  EXPECT_THAT(error_of("solver: {gravity: [.nan, 0, 0]}"),
              HasSubstr("solver.gravity: element 0: expected a number (float), got NaN ('.nan')"));
}

// A list of sections beyond the documented limit is refused before its entries are read.
TEST(ConfigErrors, SpawnListLimit) {
  std::string many = "spawn:\n";
  for (std::size_t i = 0; i <= config::kMaxSectionListEntries; ++i) many += "  - {kind: fluid_block}\n";
  EXPECT_THAT(error_of(many), HasSubstr("spawn: a list of 10001 entries; at most 10000 entries are allowed"));
}

TEST(ConfigErrors, RenderCameraRulesAreCheckedAtLoad) {
  // zoom acts only on the recorded camera of the mesh view; elsewhere it would be ignored silently.
  const std::string zoom_rule =
      "render.zoom and render.zoom_at magnify the recorded camera of the mesh view; they need "
      "render.camera: recorded and render.view: mesh";
  EXPECT_THAT(error_of("render: {camera: recorded, view: kinect, zoom: 2}"), HasSubstr(zoom_rule));
  EXPECT_THAT(error_of("render: {camera: fixed, view: mesh, zoom_at: [320, 240]}"), HasSubstr(zoom_rule));
  EXPECT_EQ(error_of("render: {camera: recorded, view: mesh, zoom: 2, zoom_at: [320, 240]}"), "");
  EXPECT_THAT(error_of("render: {camera: recorded, view: mesh, zoom_at: [1, 2, 3]}"),
              HasSubstr("render.zoom_at: expected [u, v] (two numbers), got 3"));
  EXPECT_THAT(error_of("render: {eye: [0, 1]}"), HasSubstr("render.eye: expected [x, y, z] (three numbers"));
  EXPECT_THAT(error_of("render: {target: [0, 1, 2, 3]}"), HasSubstr("render.target: expected [x, y, z]"));
  EXPECT_THAT(error_of("render: {eye: [0, 1, 2], target: [0, 1, 2]}"),
              HasSubstr("render.eye and render.target are the same point"));
  EXPECT_EQ(error_of("render: {eye: [0, 1, 2], target: [0, 1, 3]}"), "");
  // A live Kinect cannot be replayed after a scan.
  EXPECT_THAT(error_of("mode: scan_then_simulate\ninput: {source: kinect}\nrender: {camera: recorded}"),
              HasSubstr("render.camera: recorded with input.source: kinect needs mode: live"));
  EXPECT_EQ(error_of("mode: live\ninput: {source: kinect}\nrender: {camera: recorded}"), "");
  EXPECT_EQ(error_of("mode: scan_then_simulate\ninput: {source: tum}\nrender: {camera: recorded}"), "");
}

TEST(ConfigErrors, SpawnRulesAreCheckedAtLoad) {
  EXPECT_THAT(error_of("spawn:\n  - kind: rigid\n    place: {on: floor, pixel: [10, 20]}"),
              HasSubstr("spawn[0] (rigid).place: give either `on` (floor) or `pixel`, not both"));
  EXPECT_THAT(error_of("spawn:\n  - kind: cloth\n  - kind: rigid\n    place: {pixel: [10, 20, 30]}"),
              HasSubstr("spawn[1] (rigid).place.pixel: expected [u, v] (two numbers), got 3"));
  EXPECT_THAT(error_of("spawn:\n  - kind: fluid_block\n    place: {on: support, offset: [0.1]}"),
              HasSubstr("spawn[0] (fluid_block).place.offset: expected [x, z] (two numbers), got 1"));
  EXPECT_THAT(error_of("spawn:\n  - kind: fluid_block\n    place: {offset: [0.1, 0.2]}"),
              HasSubstr("spawn[0] (fluid_block).place.offset moves an `on:` placement across its surface; it needs "
                        "`on: support` or `on: floor`"));
  EXPECT_EQ(error_of("spawn:\n  - kind: fluid_block\n    place: {on: support, offset: [0.1, 0.2]}"), "");
  EXPECT_EQ(error_of("spawn:\n  - kind: rigid\n    place: {pixel: [10, 20], frame: 3}"), "");
  // A mesh body needs its file.
  EXPECT_THAT(error_of("spawn:\n  - kind: cloth\n  - kind: rigid\n    shape: mesh"),
              HasSubstr("spawn[1] (rigid): spawn.1.shape: mesh needs the key spawn.1.mesh"));
  EXPECT_EQ(error_of("spawn:\n  - kind: rigid\n    shape: mesh\n    mesh: bunny.obj"), "");
  EXPECT_EQ(error_of("spawn:\n  - kind: fluid_block\n    shape: mesh"), "");  // shape is a rigid key
}

TEST(ConfigErrors, TrackerRulesAreCheckedAtLoad) {
  EXPECT_THAT(error_of("tracker: {gravity: fixed, fixed_gravity: [0, 0, 0]}"),
              HasSubstr("tracker.gravity: fixed needs a direction, but tracker.fixed_gravity is the zero vector"));
  EXPECT_EQ(error_of("tracker: {gravity: fixed, fixed_gravity: [0, 0, 1]}"), "");
  EXPECT_EQ(error_of("tracker: {gravity: none, fixed_gravity: [0, 0, 0]}"), "");  // not used
}

TEST(ConfigErrors, ListElementsHaveIndexedPathsAndPositions) {
  std::string msg = error_of("spawn:\n  - kind: rigid\n  - kind: fluid_blok\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:3:11: spawn.1.kind"));
  EXPECT_THAT(msg, HasSubstr("did you mean 'fluid_block'?"));
}

TEST(ConfigErrors, AllProblemsAreReportedAtOnce) {
  std::string msg = error_of("volume:\n  voxel_size: 5\n  layot: hash\nrender: {width: wide}\n");
  EXPECT_THAT(msg, HasSubstr("3 problems"));
  EXPECT_THAT(msg, HasSubstr("test.yaml:2:15: volume.voxel_size"));
  EXPECT_THAT(msg, HasSubstr("test.yaml:3:3: volume.layot"));
  EXPECT_THAT(msg, HasSubstr("render.width"));
}

TEST(ConfigErrors, ProblemsAreListedInFileOrder) {
  // The unknown key is found after its section was read, but is listed where it stands.
  std::string msg = error_of("volume:\n  layot: hash\n  voxel_size: 5\n", {"render.width=0"});
  auto unknown = msg.find("test.yaml:2:3: volume.layot"), range = msg.find("test.yaml:3:15: volume.voxel_size");
  auto set = msg.find("(from --set render.width=0): render.width: out of range");
  ASSERT_NE(unknown, std::string::npos) << msg;
  ASSERT_NE(range, std::string::npos) << msg;
  ASSERT_NE(set, std::string::npos) << msg;
  EXPECT_LT(unknown, range);
  EXPECT_LT(range, set);  // overrides after the file
}

TEST(ConfigErrors, DuplicateKey) {
  EXPECT_THAT(error_of("volume:\n  voxel_size: 0.01\n  voxel_size: 0.02\n"),
              HasSubstr("test.yaml:3:3: volume.voxel_size: duplicate key"));
}

TEST(ConfigErrors, YamlSyntaxErrorHasPosition) {
  std::string msg = error_of("volume:\n  voxel_size: [0.01\n");
  EXPECT_THAT(msg, HasSubstr("test.yaml:"));
  EXPECT_THAT(msg, HasSubstr("YAML syntax error"));
}

TEST(ConfigErrors, FileErrorsNameTheFile) {
  auto dir = std::filesystem::path(::testing::TempDir()) / "seamless_config_errors";
  std::filesystem::create_directories(dir);
  std::string file = (dir / "bad.yaml").string();
  std::ofstream(file) << "render:\n  mode: headles\n";
  try {
    load_experiment(file);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr(file + ":2:9: render.mode"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("did you mean 'headless'?"));
  }
  EXPECT_THROW(load_experiment((dir / "missing.yaml").string()), Error);
}

TEST(ConfigDidYouMean, PicksTheClosestPlausibleWord) {
  std::vector<std::string> keys{"voxel_size", "truncation", "max_weight", "dt", "nx"};
  EXPECT_EQ(config::did_you_mean("voxel_sise", keys), "voxel_size");
  EXPECT_EQ(config::did_you_mean("truncaton", keys), "truncation");
  EXPECT_EQ(config::did_you_mean("MAX_WEIGHT", keys), "max_weight");
  EXPECT_EQ(config::did_you_mean("dx", keys), "dt");  // one substitution; "nx" ties, first wins
  EXPECT_EQ(config::did_you_mean("colour", keys), "");
}

// Every shipped experiment file must load: a config that rots breaks users first.
TEST(ConfigFiles, EveryShippedConfigLoads) {
  std::filesystem::path root = std::filesystem::path(SEAMLESS_SOURCE_DIR) / "configs";
  int n = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    auto ext = entry.path().extension();
    if (ext != ".yaml" && ext != ".yml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW({
      try {
        load_experiment(entry.path().string());
      } catch (const Error& e) {
        ADD_FAILURE() << e.what();
        throw;
      }
    });
    ++n;
  }
  EXPECT_GE(n, 3) << "configs/demo.yaml, tum_fr1.yaml and kinect_live.yaml at least";
}

TEST(ConfigFiles, DemoSaysWhatItShould) {
  Experiment e = load_experiment(std::string(SEAMLESS_SOURCE_DIR) + "/configs/demo.yaml");
  EXPECT_EQ(e.input.source, InputSource::synthetic);
  EXPECT_EQ(e.mode, ExperimentMode::scan_then_simulate);
  // The demo's scene: fluid on the desk, a cloth, cubes (plural) on the floor.
  auto count = [&](SpawnKind kind) {
    return std::count_if(e.spawn.begin(), e.spawn.end(), [&](const SpawnParams& s) { return s.kind == kind; });
  };
  EXPECT_GE(count(SpawnKind::fluid_block) + count(SpawnKind::emitter), 1);
  EXPECT_GE(count(SpawnKind::cloth), 1);
  EXPECT_GE(count(SpawnKind::rigid), 2);
}

}  // namespace
}  // namespace seamless
