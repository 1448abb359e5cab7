#include "cvslam/simrun/render_world_choice.h"

namespace cvslam {

Expected<RenderWorldChoice> chooseRenderWorld(const sim::Scenario& scenario,
                                              const std::string& requested) {
  RenderWorldChoice choice;
  choice.options.seed = scenario.seed;
  if (requested == "aerial" || requested == "hall") {
    choice.options.kind =
        requested == "hall" ? render::WorldKind::kHall : render::WorldKind::kAerial;
    choice.reason = requested + " (requested)";
    return choice;
  }
  if (!requested.empty())
    return Status::Error("unknown world '" + requested + "' (use aerial or hall)");
  bool indoor = !scenario.agents.empty();
  for (const auto& agent : scenario.agents)
    indoor = indoor && agent.trajectory.kind == sim::TrajectoryKind::kTum;
  choice.options.kind = indoor ? render::WorldKind::kHall : render::WorldKind::kAerial;
  choice.reason = indoor ? "hall (every agent flies a recorded TUM trajectory: indoor)"
                         : "aerial (outdoor scenario)";
  return choice;
}

}  // namespace cvslam
