// cvslam_simulate — writes a simulated team as EuRoC ASL folders (docs/run_format.md): per UAV
// DIR/uav<id>/mav0/{cam0,cam1,imu0,state_groundtruth_estimate0} with rendered images, the
// simulator's IMU and ground truth, plus DIR/landmarks.csv and DIR/sensors.yaml.
//
//   cvslam_simulate --scenario config/scenarios/team3_aerial.yaml --out data/team3

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cvslam/camera/euroc_calibration.h"
#include "cvslam/dataset/euroc_dataset_writer.h"
#include "cvslam/io/cli.h"
#include "cvslam/scenario/resting_start.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/scenario/tum_trajectory.h"
#include "cvslam/sensors/merged_sensor_source.h"
#include "cvslam/simrun/as_recorded_rig.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/simulated_sensor_stream.h"

namespace {

using cvslam::Expected;
using cvslam::Status;

constexpr const char* kUsage = R"(usage: cvslam_simulate --scenario FILE --out DIR [options]

Simulates the scenario's team and writes one EuRoC ASL folder per UAV,
DIR/uav<id>/mav0/{cam0,cam1,imu0,state_groundtruth_estimate0} (rendered rectified
stereo PNGs, IMU, ground truth at the IMU rate, sensor.yaml), plus DIR/landmarks.csv
(3-D ground truth of the rendered world: the corners of its boxes, NED) and
DIR/sensors.yaml (scenario, world and per-UAV calibration summary).
Ground truth and IMU are in the scenario's NED frame; body = IMU frame (unless
--as-recorded).

options:
  --scenario FILE     scenario YAML (config/scenarios/*.yaml)            [required]
  --out DIR           output folder; must not hold uav<id>/mav0 already  [required]
  --seed N            overrides the scenario's seed
  --duration S        simulate only the first S seconds
  --world KIND        aerial | hall (default: the scenario's render: world, else hall for
                      TUM-trajectory scenarios and aerial otherwise)
  --as-recorded MAV0  write the folders as a real rig records them: z-up world,
                      IMU in the axes and images with the calibration (unrectified,
                      distorted) of the EuRoC folder MAV0 (its cam0/cam1/sensor.yaml);
                      ground truth = pose of the IMU in the z-up world
  --camera-delay S    every UAV's frames are taken S s after its IMU ticks (a camera
                      not triggered by the IMU; overrides the scenario's camera_delay_s;
                      0 <= S < one camera period)
  --quiet             no progress output
  -h, --help          this text
)";

struct Args {
  std::string scenario, out, world, as_recorded;
  long long seed = -1;
  double duration = -1.0;
  double camera_delay = -1.0;  // < 0: the scenario's
  bool quiet = false;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "cvslam_simulate: %s\n", message.c_str());
  return 2;
}

/// Fills `a`; nullopt to go on, else the exit status (0 after --help, 2 after an error).
std::optional<int> parseArgs(int argc, char** argv, Args& a) {
  CLI::App app("writes a simulated team as EuRoC ASL folders", "cvslam_simulate");
  app.add_option("--scenario", a.scenario)->required();
  app.add_option("--out", a.out)->required();
  app.add_option("--world", a.world);
  app.add_option("--seed", a.seed)->check(cvslam::cli::kCount);
  app.add_option("--duration", a.duration)->check(cvslam::cli::kPositive);
  app.add_option("--as-recorded", a.as_recorded);
  app.add_option("--camera-delay", a.camera_delay)->check(cvslam::cli::kNonNegative);
  app.add_flag("--quiet", a.quiet);
  return cvslam::cli::parse(app, argc, argv, kUsage);
}

std::string agentFolder(const std::string& out, int id) {
  return out + "/uav" + std::to_string(id);
}

// Corners of the rendered world's boxes (buildings, machines, pallets): exact 3-D points
// that the images show, the natural ground truth for a rendered world.
Status writeLandmarks(const std::string& path, const cvslam::render::World& world, bool z_up) {
  std::ofstream f(path);
  f << "# id, x [m], y [m], z [m]: corners of the rendered world's boxes, "
    << (z_up ? "z-up world of the ground truth\n" : "NED\n");
  const Eigen::Matrix3d R =
      z_up ? cvslam::AsRecordedRig::R_NtoW() : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
  f.precision(17);
  int id = 0;
  for (const auto& box : world.boxes()) {
    for (int c = 0; c < 8; ++c) {
      const double x = (c & 1) ? box.hi_N.x() : box.lo_N.x();
      const double y = (c & 2) ? box.hi_N.y() : box.lo_N.y();
      const double z = (c & 4) ? box.hi_N.z() : box.lo_N.z();
      const Eigen::Vector3d p = R * Eigen::Vector3d(x, y, z);
      f << id++ << ',' << p.x() << ',' << p.y() << ',' << p.z() << '\n';
    }
  }
  f.close();
  return f ? Status::Ok() : Status::Error("cannot write " + path);
}

std::string row(const Eigen::MatrixXd& m) {
  std::ostringstream s;
  s.precision(17);
  s << '[';
  for (Eigen::Index i = 0; i < m.size(); ++i) s << (i ? ", " : "") << m(i / m.cols(), i % m.cols());
  s << ']';
  return s.str();
}

Status writeSensorsYaml(const std::string& path, const cvslam::sim::Scenario& scenario,
                        const std::string& world_reason, const std::string& as_recorded) {
  std::ofstream f(path);
  f.precision(17);
  f << "# Written by cvslam_simulate: what was simulated, and each UAV's rectified stereo\n"
       "# camera and IMU (the same values as in uav<id>/mav0/*/sensor.yaml).\n";
  f << "scenario: " << scenario.source << "\nname: " << scenario.name << "\nseed: " << scenario.seed
    << "\nduration: " << scenario.duration << "\nrender_world: \"" << world_reason << "\"\nframe: "
    << (as_recorded.empty() ? "NED"
                            : "z-up  # as recorded: W = NED with y, z flipped; images, IMU axes "
                              "and calibration of " +
                                  as_recorded)
    << "\nagents:\n";
  for (const auto& a : scenario.agents) {
    const auto& c = a.camera;
    f << "  - id: " << a.id << "\n    folder: uav" << a.id
      << "\n    camera_rate_hz: " << a.camera_rate_hz << "\n    imu_rate_hz: " << a.imu.rate_hz
      << "\n    imu_noise: " << (a.imu.noise ? "true" : "false") << "\n    resolution: [" << c.width
      << ", " << c.height << "]\n    intrinsics: [" << c.fx << ", " << c.fy << ", " << c.cx << ", "
      << c.cy << "]\n    distortion_coefficients: [0, 0, 0, 0]\n    baseline: " << c.baseline
      << "\n    R_BtoC: " << row(c.R_BtoC) << "\n    p_CinB: " << row(c.p_CinB.transpose()) << '\n';
  }
  f.close();
  return f ? Status::Ok() : Status::Error("cannot write " + path);
}

// One UAV's output: its folder writer and, with --as-recorded, the real rig it records with.
struct AgentOutput {
  cvslam::EurocDatasetWriter writer;
  std::optional<cvslam::AsRecordedRig> rig;
  int64_t epoch_ns = 0;  // recording clock at simulation time 0
  uint64_t frames = 0;
};

// As recorded, timestamps are on a recorder's clock (EuRoC: ns since 1970). A TUM flight keeps
// its own clock (rest included: the recorder ran while the vehicle stood still); other
// flights start at a fixed date of EuRoC's era, so the numbers have a real recording's size.
int64_t recordingEpochNs(const cvslam::sim::AgentSimulator& agent) {
  constexpr int64_t kSyntheticEpochNs = 1'400'000'000'000'000'000;  // 2014-05-13
  const cvslam::sim::Trajectory* t = &agent.trajectory();
  double rest = 0.0;
  if (const auto* r = dynamic_cast<const cvslam::sim::RestingStartTrajectory*>(t)) {
    rest = r->rest();
    t = &r->base();
  }
  const auto* tum = dynamic_cast<const cvslam::sim::TumTrajectory*>(t);
  if (tum == nullptr) return kSyntheticEpochNs;
  return std::llround((tum->startTime() - rest) * 1e6) * 1000;
}

Expected<std::map<int, AgentOutput>> createOutputs(
    const Args& args, const cvslam::sim::Scenario& scenario,
    const cvslam::render::RenderOptions& render_options, const cvslam::sim::Simulator& simulator,
    std::shared_ptr<const cvslam::render::World> world) {
  std::optional<cvslam::EurocStereoCalibration> rig_calibration;
  if (!args.as_recorded.empty()) {
    auto c = cvslam::loadEurocStereoCalibration(args.as_recorded);
    if (!c.ok()) return c.status();
    rig_calibration = *c;
  }
  std::map<int, AgentOutput> outputs;
  for (const auto& a : scenario.agents) {
    cvslam::EurocWriterOptions o;
    o.camera = a.camera;
    o.camera_rate_hz = a.camera_rate_hz;
    o.imu.comment = a.imu.noise ? "cvslam simulated IMU" : "cvslam simulated IMU (noise-free)";
    o.imu.rate_hz = a.imu.rate_hz;
    o.imu.gyroscope_noise_density = a.imu.gyro_noise_density;
    o.imu.gyroscope_random_walk = a.imu.gyro_random_walk;
    o.imu.accelerometer_noise_density = a.imu.accel_noise_density;
    o.imu.accelerometer_random_walk = a.imu.accel_random_walk;
    std::optional<cvslam::AsRecordedRig> rig;
    if (rig_calibration) {
      auto r = cvslam::AsRecordedRig::create(world, *rig_calibration, a.camera, render_options);
      if (!r.ok()) return r.status();
      rig = std::move(*r);
      o.cameras = {rig->cameraInfo(false, a.camera_rate_hz),
                   rig->cameraInfo(true, a.camera_rate_hz)};
    }
    auto w = cvslam::EurocDatasetWriter::create(agentFolder(args.out, a.id), o);
    if (!w.ok()) return w.status();
    const int64_t epoch_ns = rig ? recordingEpochNs(*simulator.agentById(a.id)) : 0;
    outputs.emplace(a.id, AgentOutput{std::move(*w), std::move(rig), epoch_ns});
  }
  return outputs;
}

// Writes one event; as recorded: IMU in the rig's axes, truth in the z-up world, images
// rendered by the rig at the frame's true pose (the stream then carries features only).
Status writeEvent(const cvslam::SensorEvent& e, const cvslam::sim::Simulator& simulator,
                  AgentOutput& out) {
  cvslam::EurocDatasetWriter& w = out.writer;
  const int64_t t_ns = out.epoch_ns + e.t_us * 1000;
  if (e.type == cvslam::SensorEventType::kImu) {
    if (!out.rig) return w.addImu(e.imu);
    cvslam::ImuSample s = out.rig->imu(e.imu);
    s.t_us = t_ns / 1000;
    return w.addImu(s);
  }
  if (e.type == cvslam::SensorEventType::kGroundTruth) {
    if (out.rig) {
      cvslam::EurocGroundTruth g = out.rig->groundTruth(e.t_us, e.truth);
      g.t_ns = t_ns;
      return w.addGroundTruth(g);
    }
    cvslam::EurocGroundTruth g;
    g.t_ns = e.t_us * 1000;
    g.p_SinR = e.truth.p_BinN;
    g.q_StoR = e.truth.q_BtoN;
    g.v_SinR = e.truth.v_N;
    g.gyro_bias = e.truth.gyro_bias;
    g.accel_bias = e.truth.accel_bias;
    return w.addGroundTruth(g);
  }
  if (e.type == cvslam::SensorEventType::kStereoImage) {
    ++out.frames;
    return w.addStereoFrame(e.t_us * 1000, e.left, e.right);
  }
  if (e.type == cvslam::SensorEventType::kFeatures && out.rig) {
    const auto* agent = simulator.agentById(e.agent_id);
    if (agent == nullptr) return Status::Error("no agent " + std::to_string(e.agent_id));
    cv::Mat left, right;
    out.rig->render(cvslam::vehiclePose(agent->truth(e.t_us)), out.frames++, &left, &right);
    return w.addStereoFrame(t_ns, left, right);
  }
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, args)) return *exit_code;

  auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
  if (!scenario.ok()) return fail(scenario.status().message());
  if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
  if (args.duration > 0.0) scenario->duration = std::min(scenario->duration, args.duration);
  if (args.camera_delay >= 0.0) {
    for (cvslam::sim::AgentSpec& a : scenario->agents) {
      if (args.camera_delay * a.camera_rate_hz >= 1.0)
        return fail("--camera-delay must be shorter than UAV" + std::to_string(a.id) +
                    "'s camera period");
      a.camera_delay_s = args.camera_delay;
    }
  }

  auto world = cvslam::chooseRenderWorld(*scenario, args.world);
  if (!world.ok()) return fail(world.status().message());
  cvslam::SimulatedSensorOptions sim_options;
  sim_options.render_world = world->options;
  sim_options.render_options = world->render;
  // As recorded, the rig renders its own (distorted) images; the stream only times the frames.
  sim_options.render = args.as_recorded.empty();
  auto team = cvslam::simulateTeam(*scenario, sim_options);
  if (!team.ok()) return fail(team.status().message());
  std::shared_ptr<const cvslam::render::World> render_world = team->render_world;
  if (!render_world) {
    auto w = cvslam::render::World::create(world->options);
    if (!w.ok()) return fail(w.status().message());
    render_world = *w;
  }
  if (!args.quiet)
    std::fprintf(stderr, "cvslam_simulate: rendering world %s%s\n", world->reason.c_str(),
                 args.as_recorded.empty() ? "" : ", as recorded");

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return fail("cannot create " + args.out + ": " + ec.message());
  auto outputs = createOutputs(args, *scenario, world->render, *team->simulator, render_world);
  if (!outputs.ok()) return fail(outputs.status().message());

  cvslam::MergedSensorSource source(std::move(team->streams));
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  cvslam::SensorEvent e;
  int64_t frames = 0;
  while (source.next(e)) {
    AgentOutput& out = outputs->at(e.agent_id);
    const uint64_t before = out.frames;
    Status s = writeEvent(e, *team->simulator, out);
    if (!s.ok()) return fail(s.message());
    frames += static_cast<int64_t>(out.frames - before);
    const auto now = std::chrono::steady_clock::now();
    if (!args.quiet && now - last_print > std::chrono::seconds(1)) {
      last_print = now;
      std::fprintf(stderr, "cvslam_simulate: %.1f / %.1f s, %lld stereo pairs%s",
                   static_cast<double>(e.play_us) * 1e-6, scenario->duration,
                   static_cast<long long>(frames), tty ? "\r" : "\n");
    }
  }
  if (!source.status().ok()) return fail(source.status().message());
  for (auto& [id, out] : *outputs) {
    Status s = out.writer.close();
    if (!s.ok()) return fail(s.message());
  }
  Status s = writeLandmarks(args.out + "/landmarks.csv", *render_world, !args.as_recorded.empty());
  if (s.ok())
    s = writeSensorsYaml(args.out + "/sensors.yaml", *scenario, world->reason, args.as_recorded);
  if (!s.ok()) return fail(s.message());
  if (!args.quiet) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(
        stderr, "%scvslam_simulate: wrote %zu UAV folders, %lld stereo pairs to %s in %.1f s\n",
        tty ? "\n" : "", outputs->size(), static_cast<long long>(frames), args.out.c_str(), wall);
  }
  return 0;
}
