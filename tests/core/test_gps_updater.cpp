// GPS updates of a VSLAM vehicle (gps_updater.h): the observation Jacobian by
// finite differences for both attitude parametrisations, and a UAV that starts 4 m off,
// flies with GPS, loses it for 10 s and gets it back.
#include "cvslam/slam/gps_updater.h"
#include "shipped_config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/io/config_node.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "jacobian_check.h"
#include "nees_band.h"

namespace cvslam {
namespace {

TEST(GpsUpdater, JacobianMatchesFiniteDifferencesWithEulerAngles) {
  const Eigen::Vector3d euler(0.2, -0.3, 2.5);
  Eigen::VectorXd x(9);
  x << 3.0, -2.0, -10.0, 4.0, 0.5, -0.3, euler;
  auto h = [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return gpsPrediction(EstimatedPose::fromEuler(v.head<9>()));
  };
  const Eigen::MatrixXd J = gpsJacobian(EstimatedPose::fromEuler(x.head<9>()));
  EXPECT_TRUE(test::jacobianMatches(h, x, J));
}

TEST(GpsUpdater, JacobianMatchesFiniteDifferencesWithTheRotationErrorState) {
  EstimatedPose nominal;
  nominal.p_BinN = Eigen::Vector3d(3.0, -2.0, -10.0);
  nominal.v_B = Eigen::Vector3d(4.0, 0.5, -0.3);
  nominal.R_BtoN = rotationBodyToNav(Eigen::Vector3d(0.2, -0.3, 2.5));
  nominal.attitude = vehicle::Attitude::kErrorState;
  // x = [p, v_B, δθ] with R = R̂ Exp(δθ), at δθ = 0.
  auto h = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    EstimatedPose p = nominal;
    p.p_BinN = v.segment<3>(vehicle::kPosition);
    p.v_B = v.segment<3>(vehicle::kVelocity);
    p.R_BtoN = nominal.R_BtoN * so3::exp(Eigen::Vector3d(v.segment<3>(vehicle::kAttitude)));
    return gpsPrediction(p);
  };
  Eigen::VectorXd x(9);
  x << nominal.p_BinN, nominal.v_B, Eigen::Vector3d::Zero();
  EXPECT_TRUE(test::jacobianMatches(h, x, gpsJacobian(nominal)));
}

// One UAV on a 30 s circle, started off by a draw of σ 3 m / 3 m / 1 m (N E D), with a GPS
// receiver (5 Hz, σ 1.5 m / 3 m / 0.1 m/s) that is out from 12 to 22 s.
sim::Scenario gpsScenario(int seed) {
  const std::string yaml = R"(
name: gps_circle
seed: )" + std::to_string(seed) +
                           R"(
duration: 30.0
world: {relief_amplitude: 1.0, landmark_density: 0.8, margin: 30.0}
agents:
  - id: 1
    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, speed: 3.0,
                 heading: velocity, tilt: bank}
    initial_uncertainty: {position_sigma: [3.0, 3.0, 1.0], perturb: true}
    imu: {rate_hz: 200.0, noise: true}
    camera_rate_hz: 10.0
    gps: {rate_hz: 5.0, sigma_horizontal: 1.5, sigma_vertical: 3.0, sigma_velocity: 0.1,
          outages: [{start_s: 12.0, end_s: 22.0}]}
)";
  auto s = sim::Scenario::fromString(yaml, "gps_circle.yaml");
  EXPECT_TRUE(s.ok()) << s.status().message();
  return *s;
}

struct GpsRun {
  double rms_before_outage = 0, rms_outage = 0, rms_after = 0, rms_all = 0;
  double mean_position_nees = 0;
};

/// The shipped configuration (config/agent.yaml) with GPS updates on or off.
VisualInertialSlamOptions shippedOptions(bool gps) {
  VisualInertialSlamOptions o;
  auto shipped = test::shippedAgentConfig();
  EXPECT_TRUE(shipped.ok()) << shipped.status().message();
  if (shipped.ok()) {
    const Status st = o.load(*shipped);
    EXPECT_TRUE(st.ok()) << st.message();
  }
  o.gps.enabled = gps;
  return o;
}

GpsRun runWithGps(bool enabled, int seed) {
  const VisualInertialSlamOptions options = shippedOptions(enabled);
  auto team = SimulatedTeamRun::create(gpsScenario(seed), options);
  EXPECT_TRUE(team.ok()) << team.status().message();
  double sum[3] = {0, 0, 0}, nees = 0;
  int n[3] = {0, 0, 0}, frames = 0;
  const Status s = (*team)->run([&](const SimulatedFrame& f) {
    const Eigen::VectorXd x = f.slam->vehicleState();
    const Eigen::MatrixXd P = f.slam->vehicleCovariance();
    const Eigen::Vector3d e = x.head<3>() - f.truth->p_BinN;
    const double t = 1e-6 * static_cast<double>(f.t_us);
    const int k = t < 12.0 ? 0 : (t < 22.0 ? 1 : 2);
    if (t >= 5.0) {  // after the first fixes pulled the start offset in
      sum[k] += e.squaredNorm();
      ++n[k];
      nees += e.dot(P.topLeftCorner<3, 3>().ldlt().solve(e));
      ++frames;
    }
    return Status::Ok();
  });
  EXPECT_TRUE(s.ok()) << s.message();
  GpsRun r;
  r.rms_before_outage = std::sqrt(sum[0] / n[0]);
  r.rms_outage = std::sqrt(sum[1] / n[1]);
  r.rms_after = std::sqrt(sum[2] / n[2]);
  r.rms_all = std::sqrt((sum[0] + sum[1] + sum[2]) / (n[0] + n[1] + n[2]));
  r.mean_position_nees = nees / frames;
  return r;
}

// The shipped configuration (config/agent.yaml, GPS on). Means over six seeds (one draw of the
// start offset and of the GPS noise each; measured: with GPS 0.29–1.17 m, without 1.7–5.8 m,
// position NEES 0.31–3.5, mean 1.15).
TEST(GpsUpdater, GpsPullsInAnOffsetStartAndVisionCarriesTheOutage) {
  GpsRun with, without;
  const int seeds[] = {11, 12, 13, 14, 15, 16};
  for (int seed : seeds) {
    const GpsRun a = runWithGps(false, seed), b = runWithGps(true, seed);
    without.rms_all += a.rms_all / std::size(seeds);
    with.rms_all += b.rms_all / std::size(seeds);
    with.rms_before_outage += b.rms_before_outage / std::size(seeds);
    with.rms_outage += b.rms_outage / std::size(seeds);
    with.rms_after += b.rms_after / std::size(seeds);
    with.mean_position_nees += b.mean_position_nees / std::size(seeds);
  }
  // Vision alone cannot see the start offset (global position is unobservable, §5.6).
  EXPECT_GT(without.rms_all, 1.5) << without.rms_all;
  // GPS (σ 1.5 m / 3 m at 5 Hz) pulls it in, and vision holds it through the 10 s outage.
  EXPECT_LT(with.rms_all, 0.35 * without.rms_all)
      << "with " << with.rms_all << " without " << without.rms_all;
  EXPECT_LT(with.rms_all, 0.7);
  EXPECT_LT(with.rms_outage, 1.5 * with.rms_before_outage + 0.2)
      << with.rms_outage << " before " << with.rms_before_outage;
  EXPECT_LT(with.rms_after, 0.8) << with.rms_after;
  // Not over-confident: the mean 3-dof position NEES under the χ² band of the six runs. It is
  // not consistent either: below the band (1.15 against [1.37, 5.25]), the fixes' σ doubled
  // by gps.sigma_scale 2 on purpose (docs/ins_gps.md).
  const test::NeesBand band = test::neesBand(3, static_cast<int>(std::size(seeds)));
  EXPECT_LT(with.mean_position_nees, band.hi) << with.mean_position_nees << ", band " << band.str();
  RecordProperty("mean_position_nees", std::to_string(with.mean_position_nees));
}

TEST(GpsUpdater, OptionsLoadAndRejectABadScale) {
  GpsUpdateOptions o;
  auto node = ConfigNode::fromString("enabled: true\nuse_velocity: false\nsigma_scale: 2\n", "g");
  ASSERT_TRUE(node.ok());
  ASSERT_TRUE(o.load(*node).ok());
  EXPECT_TRUE(o.enabled);
  EXPECT_FALSE(o.use_velocity);
  EXPECT_EQ(o.sigma_scale, 2.0);
  auto bad = ConfigNode::fromString("sigma_scale: 0\n", "g");
  const Status s = GpsUpdateOptions{}.load(*bad);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("sigma_scale"), std::string::npos);
}

}  // namespace
}  // namespace cvslam
