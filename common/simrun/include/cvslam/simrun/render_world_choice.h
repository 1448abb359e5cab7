#pragma once
// Which textured world (render/world.h) a scenario is rendered in, chosen here once for every
// program that renders a simulated flight (cvslam_run in process, cvslam_replay and
// cvslam_simulate for agent processes), so that all of them draw the same images:
//  - the scenario's own `render: world:` section when it has one;
//  - otherwise, from the trajectories: a scenario whose agents all fly TUM trajectories
//    (EuRoC recordings: indoor, forward-looking cameras) goes to `hall`, every other scenario
//    (circles, figures of eight, surveys above terrain, downward cameras) to `aerial`, both
//    with WorldOptions' default seed: the runs of a Monte Carlo over scenario seeds fly
//    through one world.
// An explicit request ("aerial" | "hall") overrides the kind only.
#include <string>
#include "cvslam/core/status.h"
#include "cvslam/render/stereo_renderer.h"
#include "cvslam/render/world.h"
#include "cvslam/scenario/scenario.h"

namespace cvslam {

struct RenderWorldChoice {
  render::WorldOptions options;  ///< the world to create
  render::RenderOptions render;  ///< the renderer's options (the scenario's `render: options:`)
  std::string reason;            ///< one line for the user, e.g. "aerial (outdoor scenario)"
};

/// `requested`: "" (the scenario's or chosen), "aerial" or "hall"; anything else is an error,
/// as is a `render:` section that does not parse (scenario_rendering.h).
Expected<RenderWorldChoice> chooseRenderWorld(const sim::Scenario& scenario,
                                              const std::string& requested);

}  // namespace cvslam
