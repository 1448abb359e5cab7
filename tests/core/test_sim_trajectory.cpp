// Trajectories (cvslam/sim): analytic derivatives against central finite differences,
// Euler-rate / body-rate consistency (thesis eq. 2.4), body-velocity dynamics
// (docs/conventions.md), TUM loading with the z-up → NED conversion.

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "cvslam/geometry/euler.h"
#include "cvslam/scenario/flight_trajectory.h"
#include "cvslam/scenario/position_path.h"
#include "cvslam/scenario/resting_start.h"
#include "cvslam/scenario/tum_trajectory.h"
#include "sim_test_helpers.h"
#include "test_paths.h"

namespace cvslam::sim {
namespace {

using simtest::makeFlight;
using simtest::skew;

struct Named {
  std::string name;
  std::shared_ptr<const Trajectory> traj;
  double t_end;
};

std::vector<Named> parametricTrajectories() {
  LoopPath::Params loop;
  loop.semi_axis_x = 150;
  loop.semi_axis_y = 100;
  loop.altitude_amplitude = 1.0;
  loop.period = 200;
  Figure8Path::Params f8;
  f8.period = 40;
  const std::vector<Eigen::Vector3d> wps = {
      {0, 0, -10}, {20, 5, -11}, {40, -5, -12}, {60, 10, -10}, {80, 0, -9}};
  const auto lawn = lawnmowerWaypoints({0, 0, -10}, 0.3, 50, 10, 3);
  std::vector<Eigen::Vector3d> closed = {
      {0, 0, -10}, {30, 0, -10}, {30, 30, -12}, {0, 30, -10}, {0, 0, -10}};
  std::vector<Named> out;
  out.push_back({"loop", makeFlight(std::make_shared<LoopPath>(loop)), 200});
  out.push_back({"figure8", makeFlight(std::make_shared<Figure8Path>(f8)), 40});
  out.push_back(
      {"waypoints",
       makeFlight(std::make_shared<SplinePath>(SplinePath::chordTimes(wps, 4), wps, false)), 20});
  out.push_back(
      {"lawnmower",
       makeFlight(std::make_shared<SplinePath>(SplinePath::chordTimes(lawn, 3), lawn, false),
                  TiltMode::kBank),
       50});
  out.push_back(
      {"closed",
       makeFlight(std::make_shared<SplinePath>(SplinePath::chordTimes(closed, 3), closed, true)),
       80});
  return out;
}

// Checks every derivative of one trajectory at time t by central differences.
void checkDerivatives(const Trajectory& traj, double t, const std::string& what) {
  const double h = 1e-5;
  const TrajectoryState s = traj.state(t), sp = traj.state(t + h), sm = traj.state(t - h);
  SCOPED_TRACE(what + " t=" + std::to_string(t));
  EXPECT_LT(((sp.p_BinN - sm.p_BinN) / (2 * h) - s.v_N).norm(), 1e-5 * (1 + s.v_N.norm()));
  EXPECT_LT(((sp.v_N - sm.v_N) / (2 * h) - s.a_N).norm(), 1e-5 * (1 + s.a_N.norm()));
  Eigen::Vector3d de = sp.euler - sm.euler;
  de(2) = wrapAngle(de(2));
  EXPECT_LT((de / (2 * h) - s.euler_rates).norm(), 1e-5);
  // R consistent with the Euler angles, and ω_B with both the Euler rates (eq. 2.4) and
  // the rotation's own derivative: Ṙ_BtoN = R_BtoN [ω]×.
  EXPECT_LT((s.R_NtoB - rotationNavToBody(s.euler)).norm(), 1e-12);
  EXPECT_LT((eulerRates(s.euler, s.omega_B) - s.euler_rates).norm(), 1e-9);
  const Eigen::Matrix3d dR = (sp.R_NtoB.transpose() - sm.R_NtoB.transpose()) / (2 * h);
  const Eigen::Matrix3d omega_fd = s.R_NtoB * dR;
  EXPECT_LT((omega_fd - skew(s.omega_B)).norm(), 1e-5);
  // Body-velocity dynamics: v̇_B = f_B + R_NtoB g_N − ω × v_B.
  const Eigen::Vector3d dvB = (sp.v_B() - sm.v_B()) / (2 * h);
  const Eigen::Vector3d model =
      s.specificForce_B() + s.R_NtoB * gravityNed() - s.omega_B.cross(s.v_B());
  EXPECT_LT((dvB - model).norm(), 1e-4);
}

TEST(SimTrajectory, DerivativesMatchFiniteDifferences) {
  for (const auto& n : parametricTrajectories()) {
    for (double t = 0.37; t < n.t_end; t += n.t_end / 23.0) checkDerivatives(*n.traj, t, n.name);
  }
}

// A resting start: the first pose held still, a smooth ramp into the base motion (every
// derivative continuous, so the checks hold in the rest, across the ramp and after it), then
// the base trajectory delayed by rest + ramp/2.
TEST(SimTrajectory, RestingStartIsStillThenSmoothThenTheBaseFlight) {
  for (const auto& n : parametricTrajectories()) {
    const RestingStartTrajectory traj(n.traj, 3.0, 2.0);
    for (double t = 0.05; t < 9.0; t += 0.13) checkDerivatives(traj, t, "resting " + n.name);
    const TrajectoryState base0 = n.traj->state(0.0);
    for (double t : {0.0, 1.0, 2.999}) {
      const TrajectoryState s = traj.state(t);
      EXPECT_EQ(s.p_BinN, base0.p_BinN) << n.name;
      EXPECT_EQ(s.R_NtoB, base0.R_NtoB) << n.name;
      EXPECT_EQ(s.v_N.norm() + s.a_N.norm() + s.omega_B.norm(), 0.0) << n.name;
    }
    for (double t : {5.0, 7.3, 12.0}) {
      const TrajectoryState s = traj.state(t), b = n.traj->state(t - 4.0);
      EXPECT_LT((s.p_BinN - b.p_BinN).norm(), 1e-12) << n.name;
      EXPECT_LT((s.v_N - b.v_N).norm(), 1e-12) << n.name;
      EXPECT_LT((s.a_N - b.a_N).norm(), 1e-12) << n.name;
    }
    EXPECT_DOUBLE_EQ(traj.duration(), n.traj->duration() + 4.0);
  }
}

TEST(SimTrajectory, HeadingFollowsVelocityAndTiltIsBounded) {
  for (const auto& n : parametricTrajectories()) {
    for (double t = 0.0; t < n.t_end; t += 0.5) {
      const TrajectoryState s = n.traj->state(t);
      const Eigen::Vector3d fwd_N = s.R_NtoB.transpose().col(0);
      const Eigen::Vector2d vh = s.v_N.head<2>();
      if (vh.norm() > 0.1) {
        EXPECT_GT(fwd_N.head<2>().normalized().dot(vh.normalized()), 0.999) << n.name << " " << t;
      }
      EXPECT_LE(std::abs(s.euler(0)), 25.0 * M_PI / 180 + 1e-9);
      EXPECT_LE(std::abs(s.euler(1)), 25.0 * M_PI / 180 + 1e-9);
    }
  }
}

TEST(SimTrajectory, LoopReturnsToStartAndClosedSplineIsPeriodic) {
  LoopPath::Params p;
  p.period = 200;
  LoopPath loop(p);
  EXPECT_LT((loop.at(200).value - loop.at(0).value).norm(), 1e-9);
  const std::vector<Eigen::Vector3d> closed = {
      {0, 0, -10}, {30, 0, -10}, {30, 30, -12}, {0, 30, -10}, {0, 0, -10}};
  SplinePath sp(SplinePath::chordTimes(closed, 3), closed, true);
  const double T = SplinePath::chordTimes(closed, 3).back();
  const PathPoint a = sp.at(1e-9), b = sp.at(T - 1e-9);
  EXPECT_LT((a.value - b.value).norm(), 1e-6);
  EXPECT_LT((a.d1 - b.d1).norm(), 1e-6);
  EXPECT_LT((a.d2 - b.d2).norm(), 1e-6);  // C³ across the seam
  EXPECT_LT((a.d3 - b.d3).norm(), 1e-6);
}

TEST(SimTrajectory, WaypointSplineIsC3AtKnots) {
  const std::vector<Eigen::Vector3d> wps = {{0, 0, 0}, {10, 3, -1}, {17, -4, 2}, {30, 0, 0}};
  const std::vector<double> t = {0, 3, 5, 9};
  SplinePath sp(t, wps, false);
  for (double tk : {3.0, 5.0}) {
    const PathPoint a = sp.at(tk - 1e-9), b = sp.at(tk + 1e-9);
    EXPECT_LT((a.value - b.value).norm(), 1e-6);
    EXPECT_LT((a.d1 - b.d1).norm(), 1e-6);
    EXPECT_LT((a.d2 - b.d2).norm(), 1e-6);
    EXPECT_LT((a.d3 - b.d3).norm(), 1e-6);  // continuous jerk: continuous body rates
  }
  for (std::size_t i = 0; i < wps.size(); ++i) EXPECT_LT((sp.at(t[i]).value - wps[i]).norm(), 1e-9);
}

TEST(SimTrajectory, TumFileEurocToNed) {
  TumTrajectoryOptions o;
  o.file = test::sharedDataDir() + "/euroc/MH_01_easy.tum";
  auto traj = TumTrajectory::load(o);
  ASSERT_TRUE(traj.ok()) << traj.status().message();
  EXPECT_GT((*traj)->duration(), 170.0);
  EXPECT_NEAR((*traj)->startTime(), 1403636580.83856, 1e-6);
  // First pose in the file: (4.688, −1.787, 0.783), z up → NED (4.688, 1.787, −0.783) (within
  // the 0.1 s averaging window at the start).
  const TrajectoryState s0 = (*traj)->state(0.0);
  EXPECT_LT((s0.p_BinN - Eigen::Vector3d(4.688, 1.787, -0.783)).norm(), 0.05);
  for (double t = 5.03; t < 170.0; t += 11.3) checkDerivatives(**traj, t, "MH_01_easy");
  // The body is EuRoC's IMU frame, whose x axis points up: the synthesised accelerometer
  // reads about +g on x, like the real EuRoC IMU data.
  EXPECT_GT(s0.specificForce_B().x(), 8.0);
}

TEST(SimTrajectory, TumErrorsNameTheFile) {
  TumTrajectoryOptions o;
  o.file = "/nonexistent/x.tum";
  auto t = TumTrajectory::load(o);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("/nonexistent/x.tum"), std::string::npos);
}

}  // namespace
}  // namespace cvslam::sim
