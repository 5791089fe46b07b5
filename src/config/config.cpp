#include "config/config.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/params_yaml.hpp"
#include "core/output_file.hpp"

namespace seamless {
namespace fs = std::filesystem;

// The largest experiment file read (docs/CONFIG.md): ten thousand spawn entries of a few hundred
// bytes each fit; a file that does not is no experiment.
constexpr std::uintmax_t kMaxConfigBytes = std::uintmax_t{4} << 20;

namespace {

YAML::Node parse_yaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(source + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                      ": YAML syntax error: " + e.msg);
  }
}

}  // namespace

Experiment parse_experiment(const std::string& yaml_text, const std::vector<std::string>& overrides,
                            const std::string& source_name) {
  YAML::Node root = parse_yaml(yaml_text, source_name);
  std::vector<config::Override> applied;
  std::vector<std::string> unusable;  // --set options that cannot be applied: reported with the rest
  for (const auto& o : overrides) {
    try {
      applied.push_back(config::apply_override(root, o));
    } catch (const Error& e) {
      unusable.push_back(e.what());
    }
  }
  config::LoadContext ctx(source_name, std::move(applied), experiment_keys());
  for (const std::string& problem : unusable) ctx.problem(problem);
  Experiment e{};
  config::read_section(ctx, root, "", e);
  // The rules across keys too, in the same list as the key errors: one run shows every problem.
  // A rule that names a key whose value was refused (it kept its default) would only confuse.
  std::vector<std::string> rules;
  e.check(rules);
  for (const std::string& r : rules)
    if (!ctx.names_refused_key(r)) ctx.problem(r);
  ctx.throw_if_errors();
  return e;
}

void Experiment::validate() const {
  std::vector<std::string> problems;
  check(problems);
  if (problems.size() == 1) throw ConfigError(problems.front());
  if (problems.empty()) return;
  std::string msg = std::to_string(problems.size()) + " problems in the configuration:";
  for (const std::string& p : problems) msg += "\n  " + p;
  throw ConfigError(msg);
}

void Experiment::check(std::vector<std::string>& problems) const {
  volume.check(problems);
  tracker.check(problems);
  render.check(problems);
  solver.check(problems);
  for (std::size_t i = 0; i < spawn.size(); ++i) spawn[i].check(static_cast<int>(i), problems);
  // A focal length of 0 projects every point to the principal point: nothing can be tracked.
  if (input.intrinsics.preset == "custom" && (input.intrinsics.fx == 0.f || input.intrinsics.fy == 0.f))
    problems.push_back("input.intrinsics.fx and fy must not be 0 with preset: custom (focal lengths in pixels; got " +
                       config::format_number(input.intrinsics.fx) + " and " +
                       config::format_number(input.intrinsics.fy) + ")");
  if (render.camera == RenderCameraMode::recorded && input.source == InputSource::kinect &&
      mode != ExperimentMode::live)
    problems.push_back(
        "render.camera: recorded with input.source: kinect needs mode: live: the recorded camera replays the input "
        "after the scan, which a live Kinect cannot (each frame is drawn from its own pose in live mode); or record "
        "first (`seamless record`)");
  if (support_plane.size() > 1)
    problems.push_back("support_plane: expected [height] (one number) or [], got " +
                       std::to_string(support_plane.size()) + " numbers");
  if (!support_plane.empty() && mode != ExperimentMode::scan_then_simulate)
    problems.push_back(
        "support_plane needs mode: scan_then_simulate (it joins the floor plane, which that mode sets up)");
  if (solver.dynamic_colliders != DynamicColliders::none && mode != ExperimentMode::live)
    problems.push_back("solver.dynamic_colliders: " + std::string(enum_name(solver.dynamic_colliders)) +
                       " needs mode: live (the colliders are each frame's depth points while the camera runs)");
}

Experiment load_experiment(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (!in) throw ConfigError("cannot open config file '" + path + "' (check the path; examples are in configs/)");
  // Bounded before it is read: the YAML tree of a file takes many times its size in memory.
  std::error_code ec;
  if (const auto bytes = fs::file_size(path, ec); !ec && bytes > kMaxConfigBytes)
    throw ConfigError(path + ": " + std::to_string(bytes) + " bytes; an experiment file is at most " +
                      std::to_string(kMaxConfigBytes >> 20) + " MiB (a spawn list holds at most " +
                      std::to_string(config::kMaxSectionListEntries) + " entries; docs/CONFIG.md)");
  std::stringstream text;
  text << in.rdbuf();
  return parse_experiment(text.str(), overrides, path);
}

std::string to_yaml(const Experiment& e) {
  return "# Effective configuration of experiment '" + e.name +
         "': every key, defaults included, after --set overrides.\n"
         "# Load it back with `seamless run <this file>`; keys are described in docs/CONFIG.md.\n" +
         config::params_to_yaml(e);
}

std::string write_effective_config(const Experiment& e, const std::string& path) {
  fs::path file = path;
  std::error_code ec;
  if (fs::is_directory(file, ec) || (!path.empty() && path.back() == '/')) file /= "config.yaml";
  if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
  std::ofstream out(partial_path(file.string()));
  out << to_yaml(e);
  out.close();
  if (!out)
    throw Error("cannot write the effective config to '" + file.string() + "' (is the output folder writable?)");
  commit_partial(file.string());
  return file.string();
}

std::vector<config::KeyInfo> experiment_keys() { return config::list_keys<Experiment>(); }

std::string experiment_keys_markdown(const std::string& prefix) {
  const std::string header = "| key | type | default | allowed | meaning |\n| --- | --- | --- | --- | --- |\n";
  std::string md = header;
  auto cell = [](std::string s) {
    for (std::size_t p = 0; (p = s.find('|', p)) != std::string::npos; p += 2) s.replace(p, 1, "\\|");
    return s;
  };
  for (const auto& k : experiment_keys()) {
    if (!prefix.empty() && k.path != prefix && k.path.rfind(prefix + ".", 0) != 0) continue;
    md += "| `" + k.path + "` | " + k.type + " | " + (k.value.empty() ? "" : "`" + cell(k.value) + "`") + " | " +
          cell(k.constraint) + " | " + cell(k.doc) + " |\n";
  }
  return md == header ? "" : md;
}

std::vector<std::string> diff_experiments(const Experiment& a, const Experiment& b) {
  return config::diff_params(a, b);
}

}  // namespace seamless
