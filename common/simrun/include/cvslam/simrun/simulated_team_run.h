#pragma once
// Drives every UAV of a simulated scenario through its own VisualInertialSlam, in dataset-time
// order and deterministically (docs/architecture.md: cvslam_run's core, no transport). Each agent
// also dead-reckons the same IMU data (INS only) for comparison. A callback sees every processed
// frame; the caller decides what to record.

#include <Eigen/Core>
#include <deque>
#include <functional>
#include <memory>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/sim/simulator.h"
#include "cvslam/simrun/frame_sensing.h"
#include "cvslam/simrun/simulation_truth_oracle.h"
#include "cvslam/slam/agent_pipeline.h"
#include "cvslam/slam/agent_setup.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

/// What the callback sees after each processed stereo frame.
struct SimulatedFrame {
  int agent_id = 0;
  int64_t t_us = 0;
  /// True state at the frame, in the agent's own frame (sim::ScenarioAgent::toOwnFrame: the
  /// world unless its start is unknown).
  const sim::GroundTruth* truth = nullptr;
  const VisualInertialSlam* slam = nullptr;  ///< the agent's filter after the frame
  const FrameReport* report = nullptr;       ///< what the frame did
  const Eigen::VectorXd* x_ins = nullptr;    ///< INS-only state at the frame
  double time_ms = 0.0;                      ///< wall time of the frame's sensing [ms]
  const FrameSensing* sensing = nullptr;     ///< the agent's sensing (stats, truth)
  /// The same filter, writable: cooperation (cvslam_run --mode dc) fuses peer estimates
  /// into it right after the frame (coop/dc_cooperation.h).
  VisualInertialSlam* mutable_slam = nullptr;
  /// The agent's pipeline after the frame (what AgentRunRecorder records).
  const AgentPipeline* pipeline = nullptr;
};

class SimulatedTeamRun {
 public:
  using FrameCallback = std::function<Status(const SimulatedFrame&)>;
  /// Sees every IMU sample right after the agent's pipeline got it (centralised mode sends
  /// them to the ground station, coop/cc_batch_builder.h).
  using ImuCallback = std::function<void(int agent_id, const ImuSample& sample)>;
  /// Makes an agent's sensing (frame_sensing.h); null in create(): FeatureSensing.
  using SensingFactory =
      std::function<Expected<std::unique_ptr<FrameSensing>>(const sim::AgentSimulator&)>;

  /// Builds the simulator and one filter per agent, started at the scenario's initial
  /// estimate. The filter is told each IMU's datasheet noise (as from a sensor.yaml).
  /// `sensing` makes each agent's sensing; empty: feature-level (true landmark ids).
  static Expected<std::unique_ptr<SimulatedTeamRun>> create(
      const sim::Scenario& scenario, const VisualInertialSlamOptions& options,
      const SensingFactory& sensing = {});

  /// Runs to the end of the scenario, calling `on_frame` after every frame (a non-ok Status
  /// from it stops the run and is returned), and `on_imu` (may be empty) after every IMU sample.
  Status run(const FrameCallback& on_frame, const ImuCallback& on_imu = {});

  std::size_t agentCount() const { return agents_.size(); }
  const VisualInertialSlam& slam(std::size_t i) const { return agents_[i].pipeline->slam(); }
  AgentPipeline& pipeline(std::size_t i) { return *agents_[i].pipeline; }
  /// How agent i's filter was started (options with its IMU noise, x0, P0, t0).
  const AgentFilterSetup& setup(std::size_t i) const { return agents_[i].setup; }
  const FrameSensing& sensing(std::size_t i) const { return *agents_[i].sensing; }
  FrameSensing& sensing(std::size_t i) { return *agents_[i].sensing; }
  int agentId(std::size_t i) const { return agents_[i].id; }
  const sim::Simulator& simulator() const { return simulator_; }
  /// Agent i as the scenario describes it (its own frame in the world among others).
  const sim::ScenarioAgent& scenarioAgent(std::size_t i) const {
    return simulator_.agent(i).scenarioAgent();
  }
  /// From now on every agent's filter takes its Jacobians at the truth (the ideal EKF,
  /// slam/linearisation_oracle.h): a consistency diagnostic, `cvslam_run --linearise-at-truth`.
  /// Refused when a start is unknown (the oracle's truth is the world's).
  Status lineariseAtTruth();
  /// Agent i's truth oracle after lineariseAtTruth() (the ground station's models of that UAV
  /// take it too, cc_team_link.h); null before.
  const LinearisationOracle* truthOracle(std::size_t i) const { return agents_[i].oracle.get(); }

 private:
  // Filter and dead reckoning are the agent process's (agent_pipeline.h), so that
  // cvslam_agent reproduces this run; only the sensing is simulation's.
  struct Agent {
    int id = 0;
    std::unique_ptr<AgentPipeline> pipeline;
    std::unique_ptr<FrameSensing> sensing;
    AgentFilterSetup setup;
    /// The UAV's GPS fixes not yet used (scenario `gps:`), applied before the first frame
    /// at or after each (VisualInertialSlam::addGps; nothing happens unless gps.enabled).
    std::deque<GpsFix> gps;
    std::unique_ptr<SimulationTruthOracle> oracle;  ///< lineariseAtTruth() only
  };
  SimulatedTeamRun(sim::Simulator simulator) : simulator_(std::move(simulator)) {}

  sim::Simulator simulator_;
  std::vector<Agent> agents_;
  std::vector<int> slot_of_id_;  // agent id -> index into agents_ (−1: none)
};

}  // namespace cvslam
