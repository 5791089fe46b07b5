// input.intrinsics: which camera model a folder gets, and that preset auto says what it chose
// (freiburg2/3 sequences were run with freiburg1's calibration without a word).
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <filesystem>

#include "io/input_params.hpp"
#include "io/intrinsics_presets.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {

// Collects what spdlog's default logger says while it lives.
struct LogCapture {
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(16);
  LogCapture() { spdlog::default_logger()->sinks().push_back(sink); }
  ~LogCapture() { spdlog::default_logger()->sinks().pop_back(); }
  std::string text() const {
    std::string all;
    for (const auto& line : sink->last_formatted()) all += line;
    return all;
  }
};

IntrinsicsParams preset(const std::string& name) {
  IntrinsicsParams p;
  p.preset = name;
  return p;
}

}  // namespace

TEST(Intrinsics, FolderNamesTellTheTumCamera) {
  EXPECT_EQ(camera_in_folder_name("rgbd_dataset_freiburg1_desk"), "freiburg1");
  EXPECT_EQ(camera_in_folder_name("rgbd_dataset_freiburg3_long_office_household"), "freiburg3");
  EXPECT_EQ(camera_in_folder_name("tum_fr1_rpy_000-149"), "freiburg1");
  EXPECT_EQ(camera_in_folder_name("FR2_desk"), "freiburg2");
  EXPECT_EQ(camera_in_folder_name("office-fr-3"), "freiburg3");
  // Not a camera: a longer number, "fr" inside a word, two different cameras, nothing at all.
  EXPECT_EQ(camera_in_folder_name("fr10"), "");
  EXPECT_EQ(camera_in_folder_name("buffr1"), "");
  EXPECT_EQ(camera_in_folder_name("fr1_vs_fr2"), "");
  EXPECT_EQ(camera_in_folder_name("frames_box_50"), "");
  EXPECT_EQ(camera_in_folder_name("fr4"), "");
  // The Bonn RGB-D Dynamic dataset's Asus Xtion: its own folder names and ours.
  EXPECT_EQ(camera_in_folder_name("rgbd_bonn_crowd"), "bonn");
  EXPECT_EQ(camera_in_folder_name("bonn_crowd_220-279"), "bonn");
  EXPECT_EQ(camera_in_folder_name("bonnet"), "");
  EXPECT_EQ(camera_in_folder_name("fr1_vs_bonn"), "");
}

TEST(Intrinsics, BonnPresetIsTheDatasetsPublishedXtion) {
  // The values the dataset publishes (SOURCE.txt of ../shared/data/bonn_crowd_220-279), with distortion.
  IntrinsicsChoice c = choose_intrinsics(preset("bonn"), "");
  EXPECT_FLOAT_EQ(c.K.fx, 542.822841f);
  EXPECT_FLOAT_EQ(c.K.fy, 542.576870f);
  EXPECT_FLOAT_EQ(c.K.cx, 315.593520f);
  EXPECT_FLOAT_EQ(c.K.cy, 237.756098f);
  EXPECT_FLOAT_EQ(c.K.dist[0], 0.039903f);
  EXPECT_FLOAT_EQ(c.K.dist[1], -0.099343f);
  EXPECT_FLOAT_EQ(c.K.dist[2], -0.000730f);
  EXPECT_FLOAT_EQ(c.K.dist[3], -0.000144f);
  EXPECT_FLOAT_EQ(c.K.dist[4], 0.f);
}

TEST(Intrinsics, AutoTakesTheNamedCameraAndSaysSo) {
  TmpDir dir("rgbd_dataset_freiburg2_desk");  // the folder's name ends in ..._freiburg2_desk_<pid>
  IntrinsicsChoice c = choose_intrinsics(preset("auto"), dir.str());
  EXPECT_EQ(c.chosen, "freiburg2");
  EXPECT_FALSE(c.generic);
  // TUM's published freiburg2 calibration, with its radial distortion.
  EXPECT_FLOAT_EQ(c.K.fx, 520.9f);
  EXPECT_FLOAT_EQ(c.K.cy, 249.7f);
  EXPECT_FLOAT_EQ(c.K.dist[0], 0.2312f);
  LogCapture log;
  resolve_intrinsics(preset("auto"), dir.str());
  EXPECT_NE(log.text().find("names freiburg2"), std::string::npos) << log.text();
  EXPECT_NE(log.text().find("fx 520.9"), std::string::npos) << log.text();
}

TEST(Intrinsics, AutoWarnsLoudlyWhenItFallsBackToTheGenericSet) {
  TmpDir dir("my_living_room");
  IntrinsicsChoice c = choose_intrinsics(preset("auto"), dir.str());
  EXPECT_TRUE(c.generic);
  EXPECT_EQ(c.chosen, "kinect_v1");
  EXPECT_FLOAT_EQ(c.K.fx, 525.f);
  EXPECT_FLOAT_EQ(c.K.cx, 319.5f);
  LogCapture log;
  resolve_intrinsics(preset("auto"), dir.str());
  EXPECT_NE(log.text().find("[warning]"), std::string::npos) << log.text();
  EXPECT_NE(log.text().find("GENERIC"), std::string::npos) << log.text();
  EXPECT_NE(log.text().find("fx 525 fy 525 cx 319.5 cy 239.5"), std::string::npos) << log.text();
}

TEST(Intrinsics, CalibrationFileWinsOverTheName) {
  TmpDir dir("fr1_recorded");
  Intrinsics K;
  K.fx = 600.f, K.fy = 601.f, K.cx = 300.f, K.cy = 200.f, K.width = 320, K.height = 240;
  write_calibration(dir / "calibration.txt", K);
  IntrinsicsChoice c = choose_intrinsics(preset("auto"), dir.str());
  EXPECT_EQ(c.chosen, "calibration.txt");
  EXPECT_FALSE(c.generic);
  EXPECT_FLOAT_EQ(c.K.fx, 600.f);
  EXPECT_EQ(c.K.width, 320);
}

TEST(Intrinsics, ANamedPresetIsTakenAsGivenWithoutWarning) {
  TmpDir dir("my_living_room");
  IntrinsicsChoice c = choose_intrinsics(preset("freiburg3"), dir.str());
  EXPECT_EQ(c.chosen, "freiburg3");
  EXPECT_FALSE(c.generic);
  EXPECT_FLOAT_EQ(c.K.fx, 535.4f);
  LogCapture log;
  resolve_intrinsics(preset("freiburg3"), dir.str());
  EXPECT_EQ(log.text().find("[warning]"), std::string::npos) << log.text();
  EXPECT_NE(log.text().find("input.intrinsics.preset: freiburg3"), std::string::npos) << log.text();
}

TEST(Intrinsics, SharedFreiburg1FolderGetsFreiburg1) {
  const std::string dir = std::string(SEAMLESS_TEST_DATA) + "/tum_fr1_rpy_000-149";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "test data folder " << dir << " is absent";
  IntrinsicsChoice c = choose_intrinsics(preset("auto"), dir);
  EXPECT_EQ(c.chosen, "freiburg1");
  EXPECT_FLOAT_EQ(c.K.fx, 517.3f);
}
