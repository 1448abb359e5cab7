#pragma once
// Which textured world (render/world.h) a scenario is rendered in. Scenarios describe the
// feature-level world only, so the choice is made here, once, for cvslam_simulate and
// cvslam_replay alike: a scenario whose agents fly TUM trajectories (EuRoC machine-hall
// recordings, indoor, forward-looking cameras) goes to `hall`; every other scenario
// (circles, figures of eight, surveys above terrain, downward cameras) to `aerial`.
// An explicit request ("aerial" | "hall") overrides the choice.
#include <string>
#include "cvslam/core/status.h"
#include "cvslam/render/world.h"
#include "cvslam/sim/scenario.h"

namespace cvslam {

struct RenderWorldChoice {
  render::WorldOptions options;  ///< kind chosen, seed = the scenario's seed
  std::string reason;            ///< one line for the user, e.g. "aerial (outdoor scenario)"
};

/// `requested`: "" (choose), "aerial" or "hall"; anything else is an error.
Expected<RenderWorldChoice> chooseRenderWorld(const sim::Scenario& scenario,
                                              const std::string& requested);

}  // namespace cvslam
