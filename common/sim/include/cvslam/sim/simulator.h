#pragma once
// Scenario runner: per agent, a time-ordered stream of IMU samples and stereo frames (with
// observations and the ground truth at the frame), generated on demand (streaming: nothing is
// precomputed except the world), plus the ground-truth landmarks (thesis §5.9, §6.4).
//
// Times are integer microseconds on the grid k·round(1e6 / rate) from 0 to the duration
// (inclusive). At equal times an IMU sample comes before the frame (propagate, then update),
// and in the merged stream lower agent indices come first. Every agent has its own RNG streams
// (IMU, camera, initial state) derived from the scenario seed and its id (rng.h), so agents are
// independent and a run is reproducible.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/core/sensor_event_type.h"
#include "cvslam/core/status.h"
#include "cvslam/ins/imu_sample.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario/scenario_agent.h"
#include "cvslam/scenario/trajectory.h"
#include "cvslam/scenario/world.h"
#include "cvslam/sim/imu_simulator.h"
#include "cvslam/sim/observation_simulator.h"

namespace cvslam::sim {

struct SimEvent {
  SensorEventType type = SensorEventType::kImu;
  int agent_id = 0;
  int64_t t_us = 0;
  ImuSample imu;                  ///< valid for kImu
  StereoFrameObservations frame;  ///< valid for kFeatures (index = true landmark id)
  GroundTruth truth;              ///< valid for kFeatures: the true state at the frame
};

class AgentSimulator {
 public:
  /// Simulates the sensors of `agent` (its IMU plays the agent's recording if it has one).
  AgentSimulator(const ScenarioAgent& agent, std::shared_ptr<const World> world,
                 uint64_t scenario_seed, double duration);

  int id() const { return agent_.spec().id; }
  const AgentSpec& spec() const { return agent_.spec(); }
  /// What the scenario says of this agent without simulating it (scenario_agent.h).
  const ScenarioAgent& scenarioAgent() const { return agent_; }
  const Trajectory& trajectory() const { return *trajectory_; }
  std::shared_ptr<const Trajectory> sharedTrajectory() const { return trajectory_; }
  const StereoCamera& camera() const { return observer_.camera(); }

  /// A recorded IMU's samples from before the flight (ScenarioAgent::imuBeforeStart).
  std::vector<ImuSample> imuBeforeStart() const { return agent_.imuBeforeStart(); }

  /// Time of the next event, or INT64_MAX when the stream is over.
  int64_t peekTime() const;
  /// The next event; false (event untouched) when the stream is over.
  bool next(SimEvent& event);

  /// True state at dataset time t_us (biases: as of the last IMU sample).
  GroundTruth truth(int64_t t_us) const;
  /// Initial state for the estimator (sampled once, from its own RNG stream).
  const InitialEstimate& initialEstimate() const { return agent_.initialEstimate(); }

 private:
  ScenarioAgent agent_;
  std::shared_ptr<const Trajectory> trajectory_;
  std::shared_ptr<const World> world_;
  ImuSimulator imu_;
  ObservationSimulator observer_;
  int64_t end_us_ = 0;
  int64_t imu_period_us_ = 5000;
  int64_t cam_period_us_ = 100000;
  int64_t next_imu_us_ = 0;
  int64_t next_cam_us_ = 0;
};

class Simulator {
 public:
  /// Builds trajectories, the world (over the trajectories' area plus the margin) and agents.
  static Expected<Simulator> create(const Scenario& scenario);

  const Scenario& scenario() const { return scenario_; }
  const World& world() const { return *world_; }
  const std::vector<Landmark>& landmarks() const { return world_->landmarks(); }
  std::size_t agentCount() const { return agents_.size(); }
  AgentSimulator& agent(std::size_t i) { return agents_[i]; }
  const AgentSimulator& agent(std::size_t i) const { return agents_[i]; }
  /// The agent with this id, or nullptr.
  const AgentSimulator* agentById(int id) const;

  /// The next event over all agents, in time order; false when every stream is over.
  bool next(SimEvent& event);

 private:
  Simulator() = default;
  Scenario scenario_;
  std::shared_ptr<const World> world_;
  std::vector<AgentSimulator> agents_;
};

}  // namespace cvslam::sim
