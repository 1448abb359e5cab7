#include "cvslam/simrun/scenario_rendering.h"

#include "cvslam/io/config_node.h"

namespace cvslam {

Expected<ScenarioRendering> ScenarioRendering::parse(const sim::Scenario& scenario) {
  ScenarioRendering r;
  if (scenario.render_yaml.empty()) return r;
  auto node = ConfigNode::fromString(scenario.render_yaml, scenario.source + " render:");
  if (!node.ok()) return node.status();
  if (node->has("world")) {
    r.world.emplace();
    r.world->load(node->child("world"));
  }
  r.options.load(node->child("options"));
  if (Status s = node->finish(); !s.ok()) return s;
  return r;
}

}  // namespace cvslam
