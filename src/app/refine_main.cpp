// seamless_refine_trajectory: refines a trajectory that is already on disk (any tracker's, e.g. a
// `seamless track` run's trajectory_odometry.txt or another program's TUM file) over the frames of
// an experiment's input, without tracking again:
//   seamless_refine_trajectory CONFIG.yaml TRAJECTORY.txt OUT_DIR [--set refine.keyframe_every=5 ...]
// Writes OUT_DIR/trajectory.txt (refined), trajectory_odometry.txt (the input) and refine_stats.csv.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "recon/refine/refine.hpp"

int main(int argc, char** argv) {
  CLI::App app("refine a trajectory (TUM format) with the keyframe pose graph of refine:");
  std::string config, trajectory, out;
  std::vector<std::string> sets;
  std::string device = "cpu";
  app.add_option("config", config, "experiment file (YAML): input, preprocess and refine sections")->required();
  app.add_option("trajectory", trajectory, "trajectory to refine, one pose per input frame")->required();
  app.add_option("out", out, "output folder")->required();
  app.add_option("--set", sets, "override a config key (repeatable)");
  app.add_option("--device", device, "cpu or cuda")->check(CLI::IsMember({"cpu", "cuda"}));
  CLI11_PARSE(app, argc, argv);
  try {
    seamless::Experiment e = seamless::load_experiment(config, sets);
    seamless::Trajectory odo = seamless::read_tum_trajectory(trajectory);
    std::filesystem::create_directories(out);
    e.refine.enabled = true;
    seamless::refine_run(e.input, odo, {}, e.refine, e.preprocess,
                         device == "cuda" ? seamless::Device::CUDA : seamless::Device::CPU, out);
  } catch (const seamless::Error& err) {
    spdlog::error("{}", err.what());
    return 1;
  }
  return 0;
}
