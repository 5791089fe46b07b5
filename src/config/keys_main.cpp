// Prints the experiment key reference as Markdown (regenerates the table in docs/CONFIG.md):
//   build/src/config/seamless_config_keys > /tmp/keys.md
#include <cstdio>

#include "config/config.hpp"

int main() {
  std::fputs(seamless::experiment_keys_markdown().c_str(), stdout);
  return 0;
}
