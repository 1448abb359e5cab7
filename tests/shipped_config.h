#pragma once
// The shipped agent configuration as the tools read it: config/agent.yaml with the profile it
// names (config/profiles/, io/effective_config.h).

#include <string>

#include "cvslam/io/effective_config.h"
#include "test_paths.h"

namespace cvslam::test {

inline Expected<ConfigNode> shippedAgentConfig() {
  auto cfg = EffectiveConfig::load(sourceDir() + "/config/agent.yaml");
  if (!cfg.ok()) return cfg.status();
  if (Status s = cfg->applyProfiles({sourceDir() + "/config/profiles"}); !s.ok()) return s;
  return cfg->node();
}

}  // namespace cvslam::test
