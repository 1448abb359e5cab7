// GPS receiver simulator (sim/gps_simulator.h): rate, outages, noise statistics per kind,
// bias random walk and option validation match its options.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "cvslam/io/config_node.h"
#include "cvslam/scenario/flight_trajectory.h"
#include "cvslam/scenario/trajectory_spec.h"
#include "cvslam/sim/gps_simulator.h"

namespace cvslam::sim {
namespace {

std::shared_ptr<const Trajectory> circle() {
  TrajectorySpec spec;  // default: a circle
  auto t = spec.build();
  EXPECT_TRUE(t.ok());
  return t.value();
}

struct Moments {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), std = Eigen::Vector3d::Zero();
  Eigen::Vector3d kurtosis = Eigen::Vector3d::Zero();
};

/// Moments of the position errors (vel = false) or the velocity errors of the fixes.
Moments errorMoments(const std::vector<GpsFix>& fixes, const Trajectory& traj, bool vel) {
  std::vector<Eigen::Vector3d> e;
  for (const GpsFix& f : fixes) {
    const TrajectoryState s = traj.state(1e-6 * static_cast<double>(f.t_us));
    e.push_back(vel ? Eigen::Vector3d(f.v_N - s.v_N) : Eigen::Vector3d(f.p_N - s.p_BinN));
  }
  Moments m;
  const double n = static_cast<double>(e.size());
  for (const auto& x : e) m.mean += x / n;
  Eigen::Vector3d m2 = Eigen::Vector3d::Zero(), m4 = Eigen::Vector3d::Zero();
  for (const auto& x : e) {
    const Eigen::Vector3d d = x - m.mean;
    m2 += d.cwiseAbs2() / n;
    m4 += d.cwiseAbs2().cwiseAbs2() / n;
  }
  m.std = m2.cwiseSqrt();
  m.kurtosis = m4.cwiseQuotient(m2.cwiseAbs2());
  return m;
}

TEST(GpsSimulator, RateAndOutagesMatchOptions) {
  GpsOptions o;
  o.rate_hz = 4.0;
  o.outages = {{10.0, 15.0}, {20.0, 22.5}};
  GpsSimulator gps(circle(), o, 3);
  const std::vector<GpsFix> fixes = gps.fixes(30.0);
  // 0..30 s at 4 Hz is 121 fixes; the outages remove 20 + 10.
  EXPECT_EQ(fixes.size(), 121u - 20u - 10u);
  for (std::size_t i = 1; i < fixes.size(); ++i) {
    const double t = 1e-6 * static_cast<double>(fixes[i].t_us);
    EXPECT_FALSE(o.inOutage(t)) << t;
    const double gap = 1e-6 * static_cast<double>(fixes[i].t_us - fixes[i - 1].t_us);
    EXPECT_TRUE(std::abs(gap - 0.25) < 1e-9 || std::abs(gap - 5.25) < 1e-9 ||
                std::abs(gap - 2.75) < 1e-9)
        << gap;
  }
}

TEST(GpsSimulator, GaussianNoiseStdMatchesOptions) {
  GpsOptions o;
  o.rate_hz = 50.0;
  o.sigma_horizontal = 2.0;
  o.sigma_vertical = 4.0;
  o.sigma_velocity = 0.3;
  auto traj = circle();
  GpsSimulator gps(traj, o, 7);
  const std::vector<GpsFix> fixes = gps.fixes(400.0);  // 20001 fixes: std to ~1 %
  const Moments p = errorMoments(fixes, *traj, false), v = errorMoments(fixes, *traj, true);
  const Eigen::Vector3d sp(2.0, 2.0, 4.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(p.std(i), sp(i), 0.03 * sp(i));
    EXPECT_NEAR(v.std(i), 0.3, 0.03 * 0.3);
    EXPECT_NEAR(p.mean(i), 0.0, 4.0 * sp(i) / std::sqrt(20001.0));
    EXPECT_NEAR(p.kurtosis(i), 3.0, 0.25);  // Gaussian
    EXPECT_DOUBLE_EQ(fixes[0].sigma_p(i), sp(i));
  }
}

TEST(GpsSimulator, HeavyTailedKindsKeepTheStdButNotTheTails) {
  for (GpsNoiseKind kind : {GpsNoiseKind::kStudentT, GpsNoiseKind::kMixture}) {
    GpsOptions o;
    o.rate_hz = 50.0;
    o.kind = kind;
    // Kurtosis: Student-t 3 + 6/(ν − 4) = 4 for ν = 10 (ν > 8 so that the sample kurtosis has a
    // finite variance); the mixture's 3·(0.9 + 0.1·256)/2.5² ≈ 12.7.
    o.student_dof = 10;
    o.sigma_horizontal = 1.0;
    auto traj = circle();
    GpsSimulator gps(traj, o, 11);
    const Moments p = errorMoments(gps.fixes(600.0), *traj, false);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(p.std(i), 1.0, 0.06);
      EXPECT_GT(p.kurtosis(i), kind == GpsNoiseKind::kStudentT ? 3.4 : 6.0);  // Gaussian: 3
    }
  }
}

TEST(GpsSimulator, BiasRandomWalkGrowsLikeItsDensity) {
  // Var b(T) = σ_rw² T per axis: over many independent receivers, the spread at T matches.
  GpsOptions o;
  o.rate_hz = 10.0;
  o.sigma_horizontal = o.sigma_vertical = o.sigma_velocity = 0.0;
  o.bias_random_walk = 0.5;
  auto traj = circle();
  const double T = 20.0;
  double sum2 = 0.0;
  const int n = 400;
  for (int s = 0; s < n; ++s) {
    GpsSimulator gps(traj, o, 100 + static_cast<uint64_t>(s));
    const std::vector<GpsFix> fixes = gps.fixes(T);
    const TrajectoryState truth = traj->state(T);
    sum2 += (fixes.back().p_N - truth.p_BinN).squaredNorm() / 3.0;
  }
  const double var = sum2 / n, expected = 0.5 * 0.5 * T;
  EXPECT_NEAR(var, expected, 0.15 * expected);  // 1200 samples: relative std ≈ 4 %
}

TEST(GpsSimulator, InvalidOptionsAreRejectedWithTheKey) {
  auto cfg = ConfigNode::fromString(
      "rate_hz: 0\nstudent_dof: 2\noutages: [{start_s: 5, end_s: 4}]\n", "gps.yaml");
  ASSERT_TRUE(cfg.ok());
  GpsOptions o;
  const Status st = o.load(*cfg);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("end_s"), std::string::npos) << st.message();
  auto cfg2 = ConfigNode::fromString("rate_hz: -1\n", "gps.yaml");
  GpsOptions o2;
  const Status st2 = o2.load(*cfg2);
  ASSERT_FALSE(st2.ok());
  EXPECT_NE(st2.message().find("rate_hz"), std::string::npos) << st2.message();
}

}  // namespace
}  // namespace cvslam::sim
