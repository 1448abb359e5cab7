#include "cvslam/sim/simulator.h"

#include <cmath>

#include "cvslam/geometry/euler.h"

namespace cvslam::sim {

namespace {

int64_t periodUs(double rate_hz) {
  return std::max<int64_t>(1, std::llround(1e6 / rate_hz));
}

}  // namespace

AgentSimulator::AgentSimulator(const ScenarioAgent& agent, std::shared_ptr<const World> world,
                               uint64_t scenario_seed, double duration)
    : agent_(agent),
      trajectory_(agent.trajectory()),
      world_(std::move(world)),
      imu_(trajectory_, agent.spec().imu,
           deriveSeed(scenario_seed, agent.spec().id, RngStream::kImu),
           agent.spec().trajectory.time_offset),
      observer_(agent.spec().camera, agent.spec().pixel_noise,
                deriveSeed(scenario_seed, agent.spec().id, RngStream::kCamera)),
      end_us_(std::llround(duration * 1e6)),
      imu_period_us_(periodUs(agent.spec().imu.rate_hz)),
      cam_period_us_(periodUs(agent.spec().camera_rate_hz)),
      next_cam_us_(std::llround(agent.spec().camera_delay_s * 1e6)) {
  if (agent.imuRecording()) imu_.useRecording(agent.imuRecording(), agent.imuRecordingTimeAtZero());
}

GroundTruth AgentSimulator::truth(int64_t t_us) const {
  GroundTruth g = agent_.motionAt(t_us);
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
  event.agent_id = id();
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
      trajectory_->state(1e-6 * static_cast<double>(t) + agent_.spec().trajectory.time_offset);
  event.frame = observer_.observe(t, s, *world_);
  event.truth = truth(t);
  next_cam_us_ += cam_period_us_;
  return true;
}

Expected<Simulator> Simulator::create(const Scenario& scenario) {
  Simulator sim;
  sim.scenario_ = scenario;
  std::vector<ScenarioAgent> agents;
  for (const AgentSpec& spec : scenario.agents) {
    auto agent = ScenarioAgent::create(scenario, spec);
    if (!agent.ok()) return agent.status();
    agents.push_back(std::move(*agent));
  }
  auto world = scenario.generateWorld();
  if (!world.ok()) return world.status();
  sim.world_ = std::make_shared<const World>(std::move(*world));
  for (const ScenarioAgent& agent : agents)
    sim.agents_.emplace_back(agent, sim.world_, scenario.seed, scenario.duration);
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
