// The experiment configuration API for the app. No yaml-cpp in this header; the generic
// visitors are in config/params_text.hpp (writer, key list, diff) and config/params_yaml.hpp
// (reader, --set). The format and the error messages are described in docs/CONFIG.md.
#pragma once
#include <string>
#include <vector>

#include "config/experiment.hpp"
#include "config/params_text.hpp"
#include "core/error.hpp"

namespace seamless {

// Reads a YAML experiment file, applies `overrides` ("a.b.c=value", as given to --set, in order)
// to the YAML tree, then validates and loads every key. Keys not in the file keep their defaults.
// Throws seamless::ConfigError listing every problem: "file:line:column: key.path: what was
// expected" (or "(from --set a.b=c): ..." for values that came from an override); a --set that
// cannot be applied at all is listed with the file's own problems, never instead of them.
Experiment load_experiment(const std::string& path, const std::vector<std::string>& overrides = {});

// Same from YAML text; `source_name` stands in for the file name in messages.
Experiment parse_experiment(const std::string& yaml_text, const std::vector<std::string>& overrides = {},
                            const std::string& source_name = "<config>");

// Every key, defaults included, with its doc string as a comment. Loads back to an equal Experiment.
std::string to_yaml(const Experiment& e);

// Writes to_yaml(e) to `path`; when `path` is a directory, to `path`/config.yaml. Creates missing
// parent folders. Returns the file written. Throws seamless::Error if it cannot write.
std::string write_effective_config(const Experiment& e, const std::string& path);

// Every key of the experiment with type, default, doc and constraint (for `config --list` and docs).
std::vector<config::KeyInfo> experiment_keys();
// The key reference as a Markdown table (docs/CONFIG.md embeds it); with `prefix` ("tracker",
// "volume.voxel_size") only that section's keys or that key, "" when there is none.
std::string experiment_keys_markdown(const std::string& prefix = "");

// Keys whose values differ ("path: a -> b"); empty when equal. Compares exactly.
std::vector<std::string> diff_experiments(const Experiment& a, const Experiment& b);

}  // namespace seamless
