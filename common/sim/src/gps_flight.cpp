#include "cvslam/sim/gps_flight.h"

#include <cmath>

#include "cvslam/io/config_node.h"

namespace cvslam::sim {

Status GpsFlightOptions::load(const ConfigNode& node, const std::string& base_dir) {
  Status st = trajectory.load(node.child("trajectory"), base_dir);
  if (!st.ok()) return st;
  imu.load(node.child("imu"));
  gps.load(node.child("gps"));
  node.get("duration_s", duration_s);
  int64_t seed_value = static_cast<int64_t>(seed);
  node.get("seed", seed_value);
  node.check(seed_value >= 0, "seed", "must be >= 0");
  seed = static_cast<uint64_t>(seed_value);
  node.check(duration_s > 0.0 && duration_s <= 1e5, "duration_s", "must be in (0, 100000]");
  node.check(imu.recording.empty(), "imu", "recording is not supported for INS/GPS flights");
  return node.status();
}

Expected<GpsFlight> simulateGpsFlight(const GpsFlightOptions& o) {
  auto built = o.trajectory.build();
  if (!built.ok()) return built.status();
  const std::shared_ptr<const Trajectory> trajectory = built.value();
  ImuSimulator imu(trajectory, o.imu, deriveSeed(o.seed, 0, RngStream::kImu));
  GpsSimulator gps(trajectory, o.gps, deriveSeed(o.seed, 0, RngStream::kGps));
  GpsFlight out;
  const auto n = static_cast<int64_t>(std::floor(o.duration_s * o.imu.rate_hz));
  for (int64_t k = 0; k <= n; ++k) {
    const auto t_us =
        static_cast<int64_t>(std::llround(1e6 * static_cast<double>(k) / o.imu.rate_hz));
    out.imu.push_back(imu.sample(t_us));
    const TrajectoryState s = trajectory->state(1e-6 * static_cast<double>(t_us));
    Eigen::Matrix<double, 9, 1> x;
    x << s.p_BinN, s.v_B(), s.euler;
    out.truth.push_back(x);
  }
  out.gps = gps.fixes(o.duration_s);
  // Snap fixes to the IMU clock (the filters correct at IMU sample times).
  std::size_t j = 0;
  for (GpsFix& f : out.gps) {
    while (j < out.imu.size() && out.imu[j].t_us < f.t_us) ++j;
    if (j < out.imu.size()) f.t_us = out.imu[j].t_us;
  }
  return out;
}

}  // namespace cvslam::sim
