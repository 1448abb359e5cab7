#pragma once
// A scenario's `render:` section, parsed: the textured world and the renderer's options for
// image sensing,
//   render: {world: {kind: aerial, seed: 1, ...}, options: {near: 0.05, effects: {...}}}
// (render/world.h, render/stereo_renderer.h). The scenario keeps the section as text
// (Scenario::render_yaml) so that the programs that only estimate read scenarios without the
// renderer; every program that renders parses it here, with the same errors (file, key, reason;
// unknown keys refused).

#include <optional>

#include "cvslam/core/status.h"
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/render/world.h"
#include "cvslam/scenario/scenario.h"

namespace cvslam {

struct ScenarioRendering {
  std::optional<render::WorldOptions> world;  ///< `render: world:`, when the scenario gives it
  render::RenderOptions options;              ///< `render: options:` (defaults when absent)

  static Expected<ScenarioRendering> parse(const sim::Scenario& scenario);
};

}  // namespace cvslam
