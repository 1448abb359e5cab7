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

#include "cvslam/dataset/euroc_dataset_writer.h"
#include "cvslam/io/cli.h"
#include "cvslam/sensors/merged_sensor_source.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/simulated_sensor_stream.h"
#include "cvslam/sim/scenario.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage = R"(usage: cvslam_simulate --scenario FILE --out DIR [options]

Simulates the scenario's team and writes one EuRoC ASL folder per UAV,
DIR/uav<id>/mav0/{cam0,cam1,imu0,state_groundtruth_estimate0} (rendered rectified
stereo PNGs, IMU, ground truth at the IMU rate, sensor.yaml), plus DIR/landmarks.csv
(3-D ground truth of the rendered world: the corners of its boxes, NED) and
DIR/sensors.yaml (scenario, world and per-UAV calibration summary).
Ground truth and IMU are in the scenario's NED frame; body = IMU frame.

options:
  --scenario FILE     scenario YAML (config/scenarios/*.yaml)            [required]
  --out DIR           output folder; must not hold uav<id>/mav0 already  [required]
  --seed N            overrides the scenario's seed
  --duration S        simulate only the first S seconds
  --world KIND        aerial | hall (default: hall for TUM-trajectory scenarios,
                      aerial otherwise)
  --quiet             no progress output
  -h, --help          this text
)";

struct Args {
  std::string scenario, out, world;
  long long seed = -1;
  double duration = -1.0;
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
  app.add_flag("--quiet", a.quiet);
  return cvslam::cli::parse(app, argc, argv, kUsage);
}

std::string agentFolder(const std::string& out, int id) {
  return out + "/uav" + std::to_string(id);
}

// Corners of the rendered world's boxes (buildings, machines, pallets): exact 3-D points
// that the images show, the natural ground truth for a rendered world.
Status writeLandmarks(const std::string& path, const cvslam::render::World& world) {
  std::ofstream f(path);
  f << "# id, x [m], y [m], z [m]: corners of the rendered world's boxes, NED\n";
  f.precision(17);
  int id = 0;
  for (const auto& box : world.boxes()) {
    for (int c = 0; c < 8; ++c) {
      const double x = (c & 1) ? box.hi_N.x() : box.lo_N.x();
      const double y = (c & 2) ? box.hi_N.y() : box.lo_N.y();
      const double z = (c & 4) ? box.hi_N.z() : box.lo_N.z();
      f << id++ << ',' << x << ',' << y << ',' << z << '\n';
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
                        const std::string& world_reason) {
  std::ofstream f(path);
  f.precision(17);
  f << "# Written by cvslam_simulate: what was simulated, and each UAV's rectified stereo\n"
       "# camera and IMU (the same values as in uav<id>/mav0/*/sensor.yaml).\n";
  f << "scenario: " << scenario.source << "\nname: " << scenario.name << "\nseed: " << scenario.seed
    << "\nduration: " << scenario.duration << "\nrender_world: \"" << world_reason
    << "\"\nframe: NED\nagents:\n";
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

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, args)) return *exit_code;

  auto scenario = cvslam::sim::Scenario::loadFile(args.scenario);
  if (!scenario.ok()) return fail(scenario.status().message());
  if (args.seed >= 0) scenario->seed = static_cast<uint64_t>(args.seed);
  if (args.duration > 0.0) scenario->duration = std::min(scenario->duration, args.duration);

  auto world = cvslam::chooseRenderWorld(*scenario, args.world);
  if (!world.ok()) return fail(world.status().message());
  cvslam::SimulatedSensorOptions sim_options;
  sim_options.render_world = world->options;
  auto team = cvslam::simulateTeam(*scenario, sim_options);
  if (!team.ok()) return fail(team.status().message());
  if (!args.quiet)
    std::fprintf(stderr, "cvslam_simulate: rendering world %s\n", world->reason.c_str());

  std::error_code ec;
  std::filesystem::create_directories(args.out, ec);
  if (ec) return fail("cannot create " + args.out + ": " + ec.message());
  std::map<int, cvslam::EurocDatasetWriter> writers;
  for (const auto& a : scenario->agents) {
    cvslam::EurocWriterOptions o;
    o.camera = a.camera;
    o.camera_rate_hz = a.camera_rate_hz;
    o.imu.comment = a.imu.noise ? "cvslam simulated IMU" : "cvslam simulated IMU (noise-free)";
    o.imu.rate_hz = a.imu.rate_hz;
    o.imu.gyroscope_noise_density = a.imu.gyro_noise_density;
    o.imu.gyroscope_random_walk = a.imu.gyro_random_walk;
    o.imu.accelerometer_noise_density = a.imu.accel_noise_density;
    o.imu.accelerometer_random_walk = a.imu.accel_random_walk;
    auto w = cvslam::EurocDatasetWriter::create(agentFolder(args.out, a.id), o);
    if (!w.ok()) return fail(w.status().message());
    writers.emplace(a.id, std::move(*w));
  }

  cvslam::MergedSensorSource source(std::move(team->streams));
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  cvslam::SensorEvent e;
  int64_t frames = 0;
  while (source.next(e)) {
    cvslam::EurocDatasetWriter& w = writers.at(e.agent_id);
    Status s;
    if (e.type == cvslam::SensorEventType::kImu) {
      s = w.addImu(e.imu);
    } else if (e.type == cvslam::SensorEventType::kGroundTruth) {
      cvslam::EurocGroundTruth g;
      g.t_ns = e.t_us * 1000;
      g.p_SinR = e.truth.p_BinN;
      g.q_StoR = e.truth.q_BtoN;
      g.v_SinR = e.truth.v_N;
      g.gyro_bias = e.truth.gyro_bias;
      g.accel_bias = e.truth.accel_bias;
      s = w.addGroundTruth(g);
    } else if (e.type == cvslam::SensorEventType::kStereoImage) {
      s = w.addStereoFrame(e.t_us * 1000, e.left, e.right);
      ++frames;
    }
    if (!s.ok()) return fail(s.message());
    const auto now = std::chrono::steady_clock::now();
    if (!args.quiet && now - last_print > std::chrono::seconds(1)) {
      last_print = now;
      std::fprintf(stderr, "cvslam_simulate: %.1f / %.1f s, %lld stereo pairs%s",
                   static_cast<double>(e.play_us) * 1e-6, scenario->duration,
                   static_cast<long long>(frames), tty ? "\r" : "\n");
    }
  }
  if (!source.status().ok()) return fail(source.status().message());
  for (auto& [id, w] : writers) {
    Status s = w.close();
    if (!s.ok()) return fail(s.message());
  }
  Status s = writeLandmarks(args.out + "/landmarks.csv", *team->render_world);
  if (s.ok()) s = writeSensorsYaml(args.out + "/sensors.yaml", *scenario, world->reason);
  if (!s.ok()) return fail(s.message());
  if (!args.quiet) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(
        stderr, "%scvslam_simulate: wrote %zu UAV folders, %lld stereo pairs to %s in %.1f s\n",
        tty ? "\n" : "", writers.size(), static_cast<long long>(frames), args.out.c_str(), wall);
  }
  return 0;
}
