#include "cvslam/sim/simulator.h"

#include <cmath>

#include "cvslam/geometry/euler.h"
#include "cvslam/sim/resting_start.h"
#include "cvslam/sim/tum_trajectory.h"

namespace cvslam::sim {

namespace {

int64_t periodUs(double rate_hz) {
  return std::max<int64_t>(1, std::llround(1e6 / rate_hz));
}

// ImuOptions::recording: load the file, find which file time is simulation time 0 and check
// that the recording covers the whole run.
Status attachImuRecording(const AgentSpec& spec, const Trajectory& trajectory, double duration,
                          AgentSimulator& agent) {
  const ImuOptions& o = spec.imu;
  if (o.recording.empty()) return Status::Ok();
  auto recording = ImuRecording::load(o.recording, o.recording_R_StoB);
  if (!recording.ok()) return recording.status();
  // A resting start (resting_start.h) plays the recording from `rest` seconds before the
  // trajectory's first pose: the vehicle stood there while the IMU was already recording.
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
  agent.useImuRecording(*recording, start);
  return Status::Ok();
}

}  // namespace

AgentSimulator::AgentSimulator(const AgentSpec& spec, std::shared_ptr<const Trajectory> trajectory,
                               std::shared_ptr<const World> world, uint64_t scenario_seed,
                               double duration)
    : spec_(spec),
      trajectory_(std::move(trajectory)),
      world_(std::move(world)),
      imu_(trajectory_, spec.imu, deriveSeed(scenario_seed, spec.id, RngStream::kImu),
           spec.trajectory.time_offset),
      observer_(spec.camera, spec.pixel_noise,
                deriveSeed(scenario_seed, spec.id, RngStream::kCamera)),
      end_us_(std::llround(duration * 1e6)),
      imu_period_us_(periodUs(spec.imu.rate_hz)),
      cam_period_us_(periodUs(spec.camera_rate_hz)),
      next_cam_us_(std::llround(spec.camera_delay_s * 1e6)) {
  initial_.sigma = spec.initial;
  initial_.state = truth(0);
  if (spec.initial.perturb) {
    Rng rng(deriveSeed(scenario_seed, spec.id, RngStream::kInitialState));
    GroundTruth& s = initial_.state;
    for (int i = 0; i < 3; ++i) s.p_BinN(i) += spec.initial.position_sigma(i) * rng.gaussian();
    for (int i = 0; i < 3; ++i) s.v_B(i) += spec.initial.velocity_sigma(i) * rng.gaussian();
    for (int i = 0; i < 3; ++i) s.euler(i) += spec.initial.attitude_sigma(i) * rng.gaussian();
    s.euler(2) = wrapAngle(s.euler(2));
    if (spec.initial.perturb_biases) {  // after the pose draws, which stay as they were
      for (int i = 0; i < 6; ++i) initial_.bias_draw(i) = rng.gaussian();
    }
  }
}

GroundTruth AgentSimulator::truth(int64_t t_us) const {
  const TrajectoryState s =
      trajectory_->state(1e-6 * static_cast<double>(t_us) + spec_.trajectory.time_offset);
  GroundTruth g;
  g.t_us = t_us;
  g.p_BinN = s.p_BinN;
  g.v_B = s.v_B();
  g.euler = s.euler;
  g.v_N = s.v_N;
  g.omega_B = s.omega_B;
  g.gyro_bias = imu_.gyroBias();
  g.accel_bias = imu_.accelBias();
  g.biases_known = !imu_.playsRecording();
  return g;
}

int64_t AgentSimulator::peekTime() const {
  const int64_t t = std::min(next_imu_us_, next_cam_us_);
  return t <= end_us_ ? t : std::numeric_limits<int64_t>::max();
}

bool AgentSimulator::next(SimEvent& event) {
  const int64_t t = peekTime();
  if (t == std::numeric_limits<int64_t>::max()) return false;
  event.agent_id = spec_.id;
  event.t_us = t;
  if (next_imu_us_ <= next_cam_us_) {  // IMU first at equal times
    event.type = SensorEventType::kImu;
    event.imu = imu_.sample(t);
    event.frame = StereoFrameObservations();
    next_imu_us_ += imu_period_us_;
    return true;
  }
  event.type = SensorEventType::kFeatures;
  const TrajectoryState s =
      trajectory_->state(1e-6 * static_cast<double>(t) + spec_.trajectory.time_offset);
  event.frame = observer_.observe(t, s, *world_);
  event.truth = truth(t);
  next_cam_us_ += cam_period_us_;
  return true;
}

Expected<Simulator> Simulator::create(const Scenario& scenario) {
  Simulator sim;
  sim.scenario_ = scenario;
  std::vector<std::shared_ptr<const Trajectory>> trajectories;
  // The area the world is laid out around: the whole team's (Scenario::world_region), else
  // these agents'.
  Eigen::AlignedBox2d region = scenario.world_region;
  const bool own_region = region.isEmpty();
  for (const AgentSpec& a : scenario.agents) {
    auto traj = a.trajectory.build();
    if (!traj.ok()) return traj.status();
    trajectories.push_back(*traj);
    if (own_region) extendByFlight(**traj, a.trajectory.time_offset, scenario.duration, &region);
  }
  if (region.isEmpty()) return Status::Error(scenario.source + ": no agents");
  region.min().array() -= scenario.world.margin + 1.0;
  region.max().array() += scenario.world.margin + 1.0;
  auto world =
      World::generate(scenario.world, region, deriveSeed(scenario.seed, 0, RngStream::kWorld));
  if (!world.ok()) return Status::Error(scenario.source + ": " + world.status().message());
  sim.world_ = std::make_shared<const World>(std::move(*world));
  for (std::size_t i = 0; i < scenario.agents.size(); ++i) {
    sim.agents_.emplace_back(scenario.agents[i], trajectories[i], sim.world_, scenario.seed,
                             scenario.duration);
    Status s = attachImuRecording(scenario.agents[i], *trajectories[i], scenario.duration,
                                  sim.agents_.back());
    if (!s.ok()) return Status::Error(scenario.source + ": " + s.message());
  }
  return sim;
}

const AgentSimulator* Simulator::agentById(int id) const {
  for (const AgentSimulator& a : agents_)
    if (a.id() == id) return &a;
  return nullptr;
}

bool Simulator::next(SimEvent& event) {
  std::size_t best = agents_.size();
  int64_t best_t = std::numeric_limits<int64_t>::max();
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    const int64_t t = agents_[i].peekTime();
    if (t < best_t) {
      best_t = t;
      best = i;
    }
  }
  if (best == agents_.size()) return false;
  return agents_[best].next(event);
}

}  // namespace cvslam::sim
