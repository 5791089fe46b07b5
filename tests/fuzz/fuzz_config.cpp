// libFuzzer target: the experiment loader (YAML text plus --set overrides). Input: YAML; every
// line that starts with "--set " is taken out as an override (KEY=VALUE). An experiment that loads
// must also survive its own round trip: its effective config (config.yaml of every run) parses
// back to the same experiment.
#include <cstdlib>

#include "config/config.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view in(reinterpret_cast<const char*>(data), size);
  std::string yaml;
  std::vector<std::string> sets;
  while (!in.empty()) {
    std::size_t end = in.find('\n');
    std::string_view line = in.substr(0, end);
    if (line.substr(0, 6) == "--set ")
      sets.emplace_back(line.substr(6));
    else
      yaml.append(line).append("\n");
    in.remove_prefix(end == std::string_view::npos ? in.size() : end + 1);
  }
  seamless::fuzz::expect_error_or_success([&] {
    seamless::Experiment e = seamless::parse_experiment(yaml, sets, "fuzz.yaml");
    seamless::Experiment again = seamless::parse_experiment(seamless::to_yaml(e), {}, "effective.yaml");
    if (!seamless::diff_experiments(e, again).empty()) std::abort();
  });
  return 0;
}
