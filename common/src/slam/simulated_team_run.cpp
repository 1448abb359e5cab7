#include "cvslam/slam/simulated_team_run.h"

#include <chrono>

namespace cvslam {

Expected<std::unique_ptr<SimulatedTeamRun>> SimulatedTeamRun::create(
    const sim::Scenario& scenario, const VisualInertialSlamOptions& options,
    const SensingFactory& sensing) {
  if (auto p = options.filter.policy(); !p.ok()) return p.status();
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator.ok()) return simulator.status();
  std::unique_ptr<SimulatedTeamRun> run(new SimulatedTeamRun(std::move(*simulator)));

  const bool with_bias = options.ins.estimate_imu_bias;
  const int n = vehicle::size(with_bias);
  for (std::size_t i = 0; i < run->simulator_.agentCount(); ++i) {
    const sim::AgentSimulator& as = run->simulator_.agent(i);
    VisualInertialSlamOptions agent_options = options;
    const sim::ImuOptions& imu = as.spec().imu;
    if (imu.noise) {
      agent_options.ins.gyro_noise_density = imu.gyro_noise_density;
      agent_options.ins.accel_noise_density = imu.accel_noise_density;
      agent_options.ins.gyro_random_walk = imu.gyro_random_walk;
      agent_options.ins.accel_random_walk = imu.accel_random_walk;
    }
    const sim::InitialEstimate& init = as.initialEstimate();
    Eigen::VectorXd x0 = Eigen::VectorXd::Zero(n);
    x0 << init.state.p_BinN, init.state.v_B, init.state.euler, Eigen::VectorXd::Zero(n - 9);
    Eigen::VectorXd sigma = Eigen::VectorXd::Zero(n);
    sigma << init.sigma.position_sigma, init.sigma.velocity_sigma, init.sigma.attitude_sigma,
        Eigen::VectorXd::Zero(n - 9);
    if (with_bias) {
      sigma.segment<3>(vehicle::kAccelBias).setConstant(options.slam.initial_accel_bias_sigma);
      sigma.segment<3>(vehicle::kGyroBias).setConstant(options.slam.initial_gyro_bias_sigma);
    }
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
    Agent a{as.id(),
            VisualInertialSlam(agent_options, as.camera()),
            std::move(agent_sensing),
            InsPropagator(agent_options.ins),
            x0,
            ImuSample(),
            false};
    const Eigen::MatrixXd P0 = sigma.array().square().matrix().asDiagonal();
    if (Status s = a.slam.initialize(init.state.t_us, x0, P0); !s.ok()) {
      return Status::Error("agent " + std::to_string(a.id) + ": " + s.message());
    }
    if (a.id >= static_cast<int>(run->slot_of_id_.size())) run->slot_of_id_.resize(a.id + 1, -1);
    run->slot_of_id_[static_cast<std::size_t>(a.id)] = static_cast<int>(run->agents_.size());
    run->agents_.push_back(std::move(a));
  }
  return run;
}

Status SimulatedTeamRun::run(const FrameCallback& on_frame) {
  sim::SimEvent ev;
  FrameReport report;
  while (simulator_.next(ev)) {
    Agent& a =
        agents_[static_cast<std::size_t>(slot_of_id_[static_cast<std::size_t>(ev.agent_id)])];
    if (ev.type == sim::SimEventType::kImu) {
      if (Status s = a.slam.addImu(ev.imu); !s.ok()) return s;
      if (a.have_imu) {
        a.x_ins = a.dead_reckoning.stepMean(a.x_ins, a.last_imu, ev.imu,
                                            Eigen::VectorXd::Zero(a.dead_reckoning.noiseSize()));
      }
      a.last_imu = ev.imu;
      a.have_imu = true;
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (Status s = a.sensing->processFrame(ev, a.slam, &report); !s.ok()) {
      return Status::Error("agent " + std::to_string(a.id) +
                           " at t = " + std::to_string(static_cast<double>(ev.t_us) * 1e-6) +
                           " s: " + s.message());
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    SimulatedFrame f{a.id,     ev.t_us, &ev.truth,       &a.slam, &report,
                     &a.x_ins, ms,      a.sensing.get(), &a.slam};
    if (on_frame) {
      if (Status s = on_frame(f); !s.ok()) return s;
    }
  }
  return Status::Ok();
}

}  // namespace cvslam
