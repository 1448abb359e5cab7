#include "cvslam/scenario/scenario_agent.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "cvslam/core/random.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/scenario/resting_start.h"
#include "cvslam/scenario/tum_trajectory.h"

namespace cvslam::sim {

namespace {

// ImuOptions::recording: load the file and find which file time is simulation time 0 (the
// trajectory's first pose; a resting start plays from `rest` seconds before it, while the
// vehicle stood there and the IMU already recorded), and check that it covers the whole run.
Status attachImuRecording(const AgentSpec& spec, const Trajectory& trajectory, double duration,
                          std::shared_ptr<const ImuRecording>* recording_out,
                          double* time_at_zero) {
  const ImuOptions& o = spec.imu;
  if (o.recording.empty()) return Status::Ok();
  auto recording = ImuRecording::load(o.recording, o.recording_R_StoB);
  if (!recording.ok()) return recording.status();
  const auto* resting = dynamic_cast<const RestingStartTrajectory*>(&trajectory);
  if (resting != nullptr && resting->ramp() > 0.0)
    return Status::Error("agent " + std::to_string(spec.id) +
                         ": trajectory.rest_ramp must be 0 with imu.recording (the recording "
                         "keeps its own timing)");
  const double rest = resting != nullptr ? resting->rest() : 0.0;
  const Trajectory& base = resting != nullptr ? resting->base() : trajectory;
  double start = o.recording_start;
  if (std::isnan(start)) {
    const auto* tum = dynamic_cast<const TumTrajectory*>(&base);
    start = tum != nullptr ? tum->startTime() - rest : (*recording)->startTime();
  }
  const double first = start + spec.trajectory.time_offset;
  const double last = first + duration;
  if (first < (*recording)->startTime() || last > (*recording)->endTime()) {
    return Status::Error("agent " + std::to_string(spec.id) + ": imu.recording " + o.recording +
                         " does not cover the run (needs file time " + std::to_string(first) +
                         ".." + std::to_string(last) + " s)");
  }
  *recording_out = *recording;
  *time_at_zero = start;
  return Status::Ok();
}

}  // namespace

Expected<ScenarioAgent> ScenarioAgent::create(const Scenario& scenario, const AgentSpec& spec) {
  ScenarioAgent a;
  a.spec_ = spec;
  auto trajectory = spec.trajectory.build();
  if (!trajectory.ok()) return trajectory.status();
  a.trajectory_ = *trajectory;
  a.camera_ = StereoCamera(spec.camera);
  Status s = attachImuRecording(spec, *a.trajectory_, scenario.duration, &a.recording_,
                                &a.recording_time_at_zero_);
  if (!s.ok()) return Status::Error(scenario.source + ": " + s.message());

  // The truth at time 0, with the IMU's turn-on biases, then the draws around it.
  InitialEstimate& init = a.initial_;
  init.sigma = spec.initial;
  init.state = a.motionAt(0);
  GroundTruth& g = init.state;
  g.gyro_bias = a.turnOnGyroBias();
  g.accel_bias = a.turnOnAccelBias();
  g.biases_known = a.recording_ == nullptr;
  if (spec.initial.perturb) {
    Rng rng(deriveSeed(scenario.seed, spec.id, RngStream::kInitialState));
    for (int i = 0; i < 3; ++i) g.p_BinN(i) += spec.initial.position_sigma(i) * rng.gaussian();
    for (int i = 0; i < 3; ++i) g.v_B(i) += spec.initial.velocity_sigma(i) * rng.gaussian();
    for (int i = 0; i < 3; ++i) g.euler(i) += spec.initial.attitude_sigma(i) * rng.gaussian();
    g.euler(2) = wrapAngle(g.euler(2));
    if (spec.initial.perturb_biases) {  // after the pose draws, which stay as they were
      for (int i = 0; i < 6; ++i) init.bias_draw(i) = rng.gaussian();
    }
  }
  if (!spec.start_known) {
    const GroundTruth start = a.motionAt(0);
    a.own_in_world_ << start.p_BinN, start.euler(2);
    g = a.toOwnFrame(g);
  }
  return a;
}

GroundTruth ScenarioAgent::motionAt(int64_t t_us) const {
  const TrajectoryState s =
      trajectory_->state(1e-6 * static_cast<double>(t_us) + spec_.trajectory.time_offset);
  GroundTruth g;
  g.t_us = t_us;
  g.p_BinN = s.p_BinN;
  g.v_B = s.v_B();
  g.euler = s.euler;
  g.v_N = s.v_N;
  g.omega_B = s.omega_B;
  return g;
}

Eigen::Vector3d ScenarioAgent::toOwnFrame(const Eigen::Vector3d& p_world) const {
  return Eigen::AngleAxisd(-own_in_world_(3), Eigen::Vector3d::UnitZ()) *
         (p_world - own_in_world_.head<3>());
}

GroundTruth ScenarioAgent::toOwnFrame(const GroundTruth& world) const {
  if (spec_.start_known) return world;  // the world is the own frame (ψ not re-wrapped)
  GroundTruth g = world;
  g.p_BinN = toOwnFrame(world.p_BinN);
  g.v_N = Eigen::AngleAxisd(-own_in_world_(3), Eigen::Vector3d::UnitZ()) * world.v_N;
  // Z-Y-X Euler angles: a yaw of the frame about the down axis shifts ψ only.
  g.euler(2) = wrapAngle(world.euler(2) - own_in_world_(3));
  return g;
}

std::vector<ImuSample> ScenarioAgent::imuBeforeStart() const {
  if (!recording_) return {};
  return recording_->samplesBefore(recording_time_at_zero_ + spec_.trajectory.time_offset);
}

Eigen::Vector3d ScenarioAgent::turnOnGyroBias() const {
  return spec_.imu.noise ? spec_.imu.gyro_bias : Eigen::Vector3d::Zero();
}

Eigen::Vector3d ScenarioAgent::turnOnAccelBias() const {
  return spec_.imu.noise ? spec_.imu.accel_bias : Eigen::Vector3d::Zero();
}

}  // namespace cvslam::sim
