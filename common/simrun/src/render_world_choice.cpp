#include "cvslam/simrun/render_world_choice.h"

#include "cvslam/simrun/scenario_rendering.h"

namespace cvslam {

Expected<RenderWorldChoice> chooseRenderWorld(const sim::Scenario& scenario,
                                              const std::string& requested) {
  if (!requested.empty() && requested != "aerial" && requested != "hall")
    return Status::Error("unknown world '" + requested + "' (use aerial or hall)");
  auto rendering = ScenarioRendering::parse(scenario);
  if (!rendering.ok()) return rendering.status();
  RenderWorldChoice choice;
  choice.render = rendering->options;
  if (rendering->world) {
    choice.options = *rendering->world;
    choice.reason = "(the scenario's render: world)";
  } else {
    bool indoor = !scenario.agents.empty();
    for (const auto& agent : scenario.agents)
      indoor = indoor && agent.trajectory.kind == sim::TrajectoryKind::kTum;
    choice.options.kind = indoor ? render::WorldKind::kHall : render::WorldKind::kAerial;
    choice.reason =
        indoor ? "(every agent flies a recorded TUM trajectory: indoor)" : "(outdoor scenario)";
  }
  if (!requested.empty()) {
    choice.options.kind =
        requested == "hall" ? render::WorldKind::kHall : render::WorldKind::kAerial;
    choice.reason = "(requested)";
  }
  choice.reason =
      std::string(choice.options.kind == render::WorldKind::kHall ? "hall " : "aerial ") +
      choice.reason;
  return choice;
}

}  // namespace cvslam
