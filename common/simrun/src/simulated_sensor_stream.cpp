#include "cvslam/simrun/simulated_sensor_stream.h"

#include <cmath>
#include <optional>

#include "cvslam/geometry/euler.h"

namespace cvslam {
namespace {

class SimulatedAgentStream final : public AgentSensorStream {
 public:
  SimulatedAgentStream(std::shared_ptr<sim::Simulator> simulator, std::size_t index,
                       std::shared_ptr<const render::StereoRenderer> renderer, bool ground_truth,
                       int64_t start_us)
      : simulator_(std::move(simulator)),
        agent_(simulator_->agent(index)),
        renderer_(std::move(renderer)),
        ground_truth_(ground_truth),
        start_us_(start_us),
        end_us_(std::llround(simulator_->scenario().duration * 1e6)) {}

  int agentId() const override { return agent_.id(); }
  const Status& status() const override { return status_; }
  int64_t endPlayUs() const override { return end_us_; }

  bool next(SensorEvent& event) override {
    if (pending_truth_) {
      event = std::move(*pending_truth_);
      pending_truth_.reset();
      return true;
    }
    sim::SimEvent e;
    while (agent_.next(e)) {
      if (e.t_us < start_us_) continue;  // before the window: never rendered
      event = SensorEvent();
      event.agent_id = agent_.id();
      event.t_us = e.t_us;
      event.play_us = e.t_us;
      if (e.type == SensorEventType::kImu) {
        event.type = SensorEventType::kImu;
        event.imu = e.imu;
        if (ground_truth_) {
          // After the sample, so that the biases are those the sample was drawn with.
          SensorEvent truth;
          truth.type = SensorEventType::kGroundTruth;
          truth.agent_id = event.agent_id;
          truth.t_us = truth.play_us = e.t_us;
          truth.truth = vehiclePose(agent_.truth(e.t_us));
          pending_truth_ = std::move(truth);
        }
      } else if (renderer_) {
        event.type = SensorEventType::kStereoImage;
        render::StereoRendering r = renderer_->render(e.truth.p_BinN, e.truth.euler,
                                                      render::StereoRenderer::frameIndexAt(e.t_us));
        event.left = r.left.image;
        event.right = r.right.image;
      } else {
        event.type = SensorEventType::kFeatures;
        event.features = std::move(e.frame);
      }
      return true;
    }
    return false;
  }

 private:
  std::shared_ptr<sim::Simulator> simulator_;
  sim::AgentSimulator& agent_;
  std::shared_ptr<const render::StereoRenderer> renderer_;
  bool ground_truth_;
  int64_t start_us_;
  int64_t end_us_;
  std::optional<SensorEvent> pending_truth_;
  Status status_;
};

}  // namespace

VehiclePose vehiclePose(const sim::GroundTruth& truth) {
  VehiclePose pose;
  pose.p_BinN = truth.p_BinN;
  pose.euler = truth.euler;
  pose.q_BtoN = Eigen::Quaterniond(rotationBodyToNav<double>(truth.euler)).normalized();
  pose.v_N = truth.v_N;
  pose.gyro_bias = truth.gyro_bias;
  pose.accel_bias = truth.accel_bias;
  return pose;
}

Expected<SimulatedTeam> simulateTeam(const sim::Scenario& scenario,
                                     const SimulatedSensorOptions& options) {
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator.ok()) return simulator.status();
  SimulatedTeam team;
  team.simulator = std::make_shared<sim::Simulator>(std::move(*simulator));
  if (options.render) {
    auto world = render::World::create(options.render_world);
    if (!world.ok()) return world.status();
    team.render_world = *world;
  }
  const int64_t start_us = std::llround(options.start * 1e6);
  for (std::size_t i = 0; i < team.simulator->agentCount(); ++i) {
    std::shared_ptr<const render::StereoRenderer> renderer;
    if (options.render) {
      renderer = std::make_shared<render::StereoRenderer>(
          team.render_world, team.simulator->agent(i).camera(), options.render_options);
    }
    team.streams.push_back(std::make_unique<SimulatedAgentStream>(
        team.simulator, i, std::move(renderer), options.ground_truth, start_us));
  }
  return team;
}

}  // namespace cvslam
