#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/scenario_setup/scenario_calibration.h"
#include "cvslam/sim/gps_simulator.h"

#include "cvslam/slam/agent_setup.h"

namespace cvslam {

Expected<std::unique_ptr<SimulatedTeamRun>> SimulatedTeamRun::create(
    const sim::Scenario& scenario, const VisualInertialSlamOptions& options,
    const SensingFactory& sensing) {
  if (auto p = options.filter.policy(); !p.ok()) return p.status();
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator.ok()) return simulator.status();
  std::unique_ptr<SimulatedTeamRun> run(new SimulatedTeamRun(std::move(*simulator)));

  for (std::size_t i = 0; i < run->simulator_.agentCount(); ++i) {
    const sim::AgentSimulator& as = run->simulator_.agent(i);
    std::unique_ptr<FrameSensing> agent_sensing;
    if (sensing) {
      auto made = sensing(as);
      if (!made.ok()) {
        return Status::Error("agent " + std::to_string(as.id()) + ": " + made.status().message());
      }
      agent_sensing = std::move(made.value());
    } else {
      agent_sensing = std::make_unique<FeatureSensing>(&run->simulator_.landmarks());
    }
    AgentFilterSetup setup = simulatedAgentSetup(as.scenarioAgent(), options);
    auto pipeline = AgentPipeline::create(as.id(), setup, as.camera());
    if (!pipeline.ok()) return pipeline.status();
    Agent a{as.id(), std::move(pipeline.value()), std::move(agent_sensing), std::move(setup), {},
            nullptr};
    if (as.spec().has_gps) {
      sim::GpsSimulator gps(as.sharedTrajectory(), as.spec().gps,
                            deriveSeed(scenario.seed, as.id(), RngStream::kGps));
      const std::vector<GpsFix> fixes = gps.fixes(scenario.duration);
      a.gps.assign(fixes.begin(), fixes.end());
    }
    if (a.id >= static_cast<int>(run->slot_of_id_.size())) run->slot_of_id_.resize(a.id + 1, -1);
    run->slot_of_id_[static_cast<std::size_t>(a.id)] = static_cast<int>(run->agents_.size());
    run->agents_.push_back(std::move(a));
  }
  return run;
}

Status SimulatedTeamRun::lineariseAtTruth() {
  for (std::size_t i = 0; i < agents_.size(); ++i)
    if (!scenarioAgent(i).spec().start_known)
      return Status::Error("linearising at the truth needs every start known (agent " +
                           std::to_string(agents_[i].id) + " starts unknown)");
  for (Agent& a : agents_) {
    a.oracle = std::make_unique<SimulationTruthOracle>(a.sensing.get());
    a.pipeline->slam().setLinearisationOracle(a.oracle.get());
  }
  return Status::Ok();
}

Status SimulatedTeamRun::run(const FrameCallback& on_frame, const ImuCallback& on_imu) {
  sim::SimEvent ev;
  while (simulator_.next(ev)) {
    const auto slot = static_cast<std::size_t>(slot_of_id_[static_cast<std::size_t>(ev.agent_id)]);
    Agent& a = agents_[slot];
    AgentPipeline& p = *a.pipeline;
    if (ev.type == SensorEventType::kImu) {
      if (Status s = p.addImu(ev.imu); !s.ok()) return s;
      if (on_imu) on_imu(a.id, ev.imu);
      continue;
    }
    while (!a.gps.empty() && a.gps.front().t_us <= ev.t_us) {
      // Fixes from before the filter started (its first frame) are of no use.
      if (a.gps.front().t_us >= p.slam().time()) {
        if (Status s = p.slam().addGps(a.gps.front()); !s.ok()) return s;
      }
      a.gps.pop_front();
    }
    FrameSensing& sensing = *a.sensing;
    if (a.oracle) a.oracle->setFrameTruth(ev.truth);
    if (Status s = p.processWith(
            ev.t_us,
            [&](VisualInertialSlam& slam, FrameReport* report) {
              return sensing.processFrame(ev, slam, report);
            },
            &sensing.lastObservations(), sensing.visualResult());
        !s.ok()) {
      return s;
    }
    if (const VisualFrameResult* r = sensing.visualResult()) {
      // The agent's own work on the frame (as cvslam_agent measures it), not the rendering.
      p.setLastFrameTime(r->front_end_ms + r->association_ms + r->filter_ms);
    }
    const AgentFrame& last = p.lastFrame();
    const sim::GroundTruth own_truth = scenarioAgent(slot).toOwnFrame(ev.truth);
    SimulatedFrame f{a.id,          ev.t_us,      &own_truth,      &p.slam(), &last.report,
                     &p.insState(), last.time_ms, a.sensing.get(), &p.slam(), &p};
    if (on_frame) {
      if (Status s = on_frame(f); !s.ok()) return s;
    }
  }
  return Status::Ok();
}

}  // namespace cvslam
