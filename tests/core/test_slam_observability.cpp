// Observability-constrained updates (slam/observability_constraint.h): the projected stereo
// Jacobian annihilates the global translation and yaw, and on simulated turns (Monte Carlo
// over seeds) the filter never gains information on the absolute yaw and stays consistent.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iostream>
#include <string>

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/io/config_node.h"
#include "cvslam/scenario/scenario.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/observability_constraint.h"
#include "cvslam/slam/vehicle_propagation.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "nees_band.h"

namespace cvslam {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kInitialYawSigmaDeg = 1.0;

/// One stereo observation's Jacobians at a pose (x, Euler layout; `error_state`: the rotation
/// error state) and the yaw directions as the filter carries them: taken at slightly
/// different points than the Jacobians.
struct ConstrainedObservation {
  StereoCamera::Matrix4x9d H_v;
  StereoCamera::Matrix4x3d H_L;
  Eigen::VectorXd u_v;
  Eigen::Vector3d u_L;
};

ConstrainedObservation observationAt(const Eigen::Matrix<double, 9, 1>& x,
                                     const Eigen::Vector3d& p_L, bool error_state) {
  EstimatedPose pose = EstimatedPose::fromEuler(x);
  if (error_state) pose.attitude = vehicle::Attitude::kErrorState;
  ConstrainedObservation o;
  StereoCamera{StereoCameraOptions{}}.project(pose, p_L, &o.H_v, &o.H_L);
  EstimatedPose moved = pose;
  moved.p_BinN += Eigen::Vector3d(0.3, -0.2, 0.0);
  o.u_v = vehicle_model::yawDirection(moved, 15);
  o.u_L = yawDirectionOfPoint(p_L + Eigen::Vector3d(-0.4, 0.1, 0.0));
  return o;
}

TEST(ObservabilityConstraint, ProjectedJacobianAnnihilatesTranslationAndYaw) {
  Eigen::Matrix<double, 9, 1> x;
  x << 12.0, -7.0, -10.0, 3.0, 0.2, 0.0, 0.05, -0.03, 0.8;
  // The same pose with Euler angles and with the rotation error state.
  for (bool error_state : {false, true}) {
    ConstrainedObservation o = observationAt(x, Eigen::Vector3d(13.0, -6.0, 0.5), error_state);
    const double before = (o.H_v * o.u_v.head<9>() + o.H_L * o.u_L).norm();
    EXPECT_GT(before, 1.0);  // the unconstrained Jacobian "sees" this yaw direction
    const StereoCamera::Matrix4x9d H_v0 = o.H_v;
    constrainStereoJacobian(o.u_v, o.u_L, 1.0, &o.H_v, &o.H_L);
    EXPECT_LT((o.H_v * o.u_v.head<9>() + o.H_L * o.u_L).norm(), 1e-9);
    EXPECT_LT((o.H_v.leftCols<3>() + o.H_L).norm(), 1e-9);  // translation
    // The change is small next to the Jacobian itself (a projection, not a new model).
    EXPECT_LT((o.H_v - H_v0).norm(), 0.1 * H_v0.norm());
  }
}

TEST(ObservabilityConstraint, RangeWeightedProjectionMovesTheChangeToTheAttitude) {
  Eigen::Matrix<double, 9, 1> x;
  x << 140.0, -70.0, -10.0, 3.0, 0.2, 0.0, 0.05, -0.03, 0.8;  // far from the origin
  const Eigen::Vector3d p_L(141.0, -69.0, 0.5);
  for (bool error_state : {false, true}) {
    const ConstrainedObservation o0 = observationAt(x, p_L, error_state);
    ASSERT_GT((o0.H_v * o0.u_v.head<9>() + o0.H_L * o0.u_L).norm(), 1.0);
    // Share of the change on the position and landmark columns, per lever arm.
    auto positionShare = [&](double lever) {
      ConstrainedObservation o = o0;
      constrainStereoJacobian(o.u_v, o.u_L, lever, &o.H_v, &o.H_L);
      EXPECT_LT((o.H_v * o.u_v.head<9>() + o.H_L * o.u_L).norm(), 1e-9) << lever;  // yaw
      EXPECT_LT((o.H_v.leftCols<3>() + o.H_L).norm(), 1e-9) << lever;              // translation
      // A Jacobian that satisfies the constraint is left alone.
      ConstrainedObservation again = o;
      constrainStereoJacobian(o.u_v, o.u_L, lever, &again.H_v, &again.H_L);
      EXPECT_LT((again.H_v - o.H_v).norm() + (again.H_L - o.H_L).norm(), 1e-9) << lever;
      const double position =
          (o.H_v.leftCols<3>() - o0.H_v.leftCols<3>()).norm() + (o.H_L - o0.H_L).norm();
      const double attitude =
          (o.H_v.middleCols<3>(vehicle::kAttitude) - o0.H_v.middleCols<3>(vehicle::kAttitude))
              .norm();
      return position / (position + attitude);
    };
    // Weighted by the landmark's range (≈ 10 m), the change moves from the position columns
    // (unweighted: |e3 × p| ≈ 150 m here pulls it there) to the attitude columns.
    const double unweighted = positionShare(1.0);
    const double weighted = positionShare((p_L - x.head<3>()).norm());
    std::cout << "position share of the change: unweighted " << unweighted << ", weighted "
              << weighted << "\n";
    EXPECT_LT(weighted, 0.1 * unweighted);
  }
}

TEST(ObservabilityConstraint, ProjectionOptionIsReadAndChecked) {
  SlamOptions o;
  EXPECT_EQ(o.oc_projection, SlamOptions::OcProjection::kRangeWeighted);
  auto unweighted = ConfigNode::fromString("oc_projection: unweighted\n", "slam.yaml");
  ASSERT_TRUE(unweighted.ok());
  ASSERT_TRUE(o.load(*unweighted).ok());
  EXPECT_EQ(o.oc_projection, SlamOptions::OcProjection::kUnweighted);
  auto bad = ConfigNode::fromString("oc_projection: sideways\n", "slam.yaml");
  ASSERT_TRUE(bad.ok());
  const Status s = SlamOptions().load(*bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("oc_projection"), std::string::npos) << s.message();
  // The tilt joins the OC-EKF's constraint: alone it would do nothing, silently.
  EXPECT_FALSE(o.oc_tilt);
  auto tilt = ConfigNode::fromString(
      "error_chart: additive\nobservability_constrained: true\noc_tilt: true\n", "slam.yaml");
  ASSERT_TRUE(tilt.ok());
  ASSERT_TRUE(o.load(*tilt).ok());
  EXPECT_TRUE(o.oc_tilt);
  auto alone =
      ConfigNode::fromString("oc_tilt: true\nobservability_constrained: false\n", "s.yaml");
  ASSERT_TRUE(alone.ok());
  const Status t = SlamOptions().load(*alone);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.message().find("oc_tilt"), std::string::npos) << t.message();
}

/// u_v is the derivative of the state coordinates under a global yaw α about N's z:
/// p ↦ Rz(α) p, R ↦ Rz(α) R (Euler: ψ + α; error state: δθ = Log(R̂ᵀ Rz(α) R̂)).
TEST(ObservabilityConstraint, YawDirectionMatchesFiniteDifferences) {
  Eigen::Matrix<double, 9, 1> x;
  x << 12.0, -7.0, -10.0, 3.0, 0.2, 0.0, 0.05, -0.03, 0.8;
  const EstimatedPose euler_pose = EstimatedPose::fromEuler(x);
  const double h = 1e-6;
  const Eigen::Matrix3d Rz(Eigen::AngleAxisd(h, Eigen::Vector3d::UnitZ()));
  const Eigen::Matrix3d Rz_back(Eigen::AngleAxisd(-h, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d dp = (Rz * euler_pose.p_BinN - Rz_back * euler_pose.p_BinN) / (2.0 * h);
  const Eigen::VectorXd u_euler = vehicle_model::yawDirection(euler_pose, 9);
  const Eigen::Vector3d de =
      (eulerFromRotationNavToBody((Rz * euler_pose.R_BtoN).transpose()) - euler_pose.euler) / h;
  EXPECT_LT((u_euler.head<3>() - dp).norm(), 1e-6);
  EXPECT_LT((u_euler.segment<3>(vehicle::kAttitude) - de).norm(), 1e-6);
  EstimatedPose error_pose = euler_pose;
  error_pose.attitude = vehicle::Attitude::kErrorState;
  const Eigen::VectorXd u_error = vehicle_model::yawDirection(error_pose, 9);
  const Eigen::Vector3d dtheta =
      so3::log(error_pose.R_BtoN.transpose() * Rz * error_pose.R_BtoN) / h;
  EXPECT_LT((u_error.head<3>() - dp).norm(), 1e-6);
  EXPECT_LT((u_error.segment<3>(vehicle::kAttitude) - dtheta).norm(), 1e-6);
  EXPECT_EQ(u_error.segment<3>(vehicle::kVelocity), Eigen::Vector3d::Zero());
}

/// tiltDirections is the derivative of the state coordinates under a rigid rotation α of the
/// world about N's x or y axis (Euler: central differences of the angles of Rot(α) R; error
/// state: Log(R̂ᵀ Rot(α) R̂)), and a stereo Jacobian taken at (pose, p_ref) annihilates it.
TEST(ObservabilityConstraint, TiltDirectionsMatchFiniteDifferencesOfAWorldRotation) {
  Eigen::Matrix<double, 9, 1> x;
  x << 12.0, -7.0, -10.0, 3.0, 0.2, 0.0, 0.05, -0.03, 0.8;
  const Eigen::Vector3d p_ref(13.0, -6.0, 0.5);
  const double h = 1e-6;
  for (bool error_state : {false, true}) {
    EstimatedPose pose = EstimatedPose::fromEuler(x);
    if (error_state) pose.attitude = vehicle::Attitude::kErrorState;
    const TiltDirections n = tiltDirections(pose, p_ref);
    for (int i = 0; i < 2; ++i) {
      SCOPED_TRACE(std::string(error_state ? "error state" : "euler") + ", axis " +
                   std::to_string(i));
      const Eigen::Matrix3d fwd(Eigen::AngleAxisd(h, Eigen::Vector3d::Unit(i)));
      const Eigen::Matrix3d back(Eigen::AngleAxisd(-h, Eigen::Vector3d::Unit(i)));
      EXPECT_LT((n.block<3, 1>(vehicle::kPosition, i) -
                 (fwd * pose.p_BinN - back * pose.p_BinN) / (2.0 * h))
                    .norm(),
                1e-6);
      EXPECT_LT((n.block<3, 1>(9, i) - (fwd * p_ref - back * p_ref) / (2.0 * h)).norm(), 1e-6);
      EXPECT_EQ((n.block<3, 1>(vehicle::kVelocity, i).norm()), 0.0);
      const Eigen::Vector3d d_attitude =
          error_state
              ? Eigen::Vector3d(so3::log(pose.R_BtoN.transpose() * fwd * pose.R_BtoN) / h)
              : Eigen::Vector3d((eulerFromRotationNavToBody((fwd * pose.R_BtoN).transpose()) -
                                 eulerFromRotationNavToBody((back * pose.R_BtoN).transpose())) /
                                (2.0 * h));
      EXPECT_LT((n.block<3, 1>(vehicle::kAttitude, i) - d_attitude).norm(), 1e-6);
    }
    StereoCamera::Matrix4x9d H_v;
    StereoCamera::Matrix4x3d H_L;
    StereoCamera{StereoCameraOptions{}}.project(pose, p_ref, &H_v, &H_L);
    EXPECT_LT((H_v * n.topRows<9>() + H_L * n.bottomRows<3>()).norm(), 1e-6);
  }
}

/// Linearised at a landmark estimate 0.4 m from the first estimate, the Jacobian informs the
/// tilt about that first estimate; constrained with the tilt, it annihilates translation, yaw
/// and both tilt directions, and the change stays small.
TEST(ObservabilityConstraint, ProjectedJacobianAnnihilatesTheTiltToo) {
  Eigen::Matrix<double, 9, 1> x;
  x << 12.0, -7.0, -10.0, 3.0, 0.2, 0.0, 0.05, -0.03, 0.8;
  const Eigen::Vector3d p_L(13.0, -6.0, 0.5), p_first = p_L + Eigen::Vector3d(0.3, -0.2, 0.2);
  for (bool error_state : {false, true}) {
    ConstrainedObservation o = observationAt(x, p_L, error_state);
    EstimatedPose pose = EstimatedPose::fromEuler(x);
    if (error_state) pose.attitude = vehicle::Attitude::kErrorState;
    const TiltDirections tilt = tiltDirections(pose, p_first);
    EXPECT_GT((o.H_v * tilt.topRows<9>() + o.H_L * tilt.bottomRows<3>()).norm(), 1.0);
    const StereoCamera::Matrix4x9d H_v0 = o.H_v;
    constrainStereoJacobian(o.u_v, o.u_L, 10.0, &o.H_v, &o.H_L, &tilt);
    EXPECT_LT((o.H_v * tilt.topRows<9>() + o.H_L * tilt.bottomRows<3>()).norm(), 1e-9);
    EXPECT_LT((o.H_v * o.u_v.head<9>() + o.H_L * o.u_L).norm(), 1e-9);
    EXPECT_LT((o.H_v.leftCols<3>() + o.H_L).norm(), 1e-9);
    EXPECT_LT((o.H_v - H_v0).norm(), 0.1 * H_v0.norm());
  }
}

TEST(ObservabilityConstraint, PropagatedYawDirectionFollowsErrorStateResets) {
  // A global yaw is an exact symmetry of the INS, so Φ maps the yaw direction of the state at
  // t_k onto that of t_k+1 — provided u_v's error-state attitude part R̂ᵀe3 is taken at the
  // nominal Φ is linearised at. Every update folds δθ into R̂ (a reset); before this was
  // handled the stored u_v kept the previous R̂ᵀe3 and its position part drifted off e3 × p
  // (thesis_loop seed 103: UAV2 61.5 m, NEES 10 895 with the error state; 8.5 m, NEES 19 after).
  const VariableKey key = VariableKey::vehicle(1);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(vehicle::kSizeNoBias);
  x.head<3>() << 3.0, -4.0, -10.0;
  x.segment<3>(vehicle::kVelocity) << 2.0, 0.3, 0.0;
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()));
  SlamState state;
  ASSERT_TRUE(
      vehicle_model::addVehicle(state, key, x, q0, Eigen::MatrixXd::Identity(9, 9) * 0.01).ok());
  LandmarkBook book;
  book.setVehicleYawDirection(
      vehicle_model::yawDirection(vehicle_model::pose(state, *state.find(key)), 9));
  InsPropagatorOptions ins_options;
  ins_options.attitude = vehicle::Attitude::kErrorState;
  const InsPropagator ins(ins_options);
  VehiclePropagation propagation;
  propagation.reset(0);
  int64_t t_us = 0;
  for (int k = 1; k <= 20; ++k) {
    for (int i = 0; i < 20; ++i) {  // 200 Hz for 0.1 s, turning and climbing
      t_us += 5000;
      ASSERT_TRUE(
          propagation
              .addImu({t_us, Eigen::Vector3d(0.02, -0.01, 0.3), Eigen::Vector3d(0.3, 0.1, -9.9)})
              .ok());
    }
    ASSERT_TRUE(propagation.propagateTo(t_us, ins, UpdatePolicy::ekf(), key, state, book).ok());
    // An update's reset: R̂ ← R̂ Exp(δθ).
    const Eigen::Vector3d delta(0.01, -0.02, 0.05);
    state.setNominalAttitude(
        key,
        (*state.nominalAttitude(key) * Eigen::Quaterniond(so3::exp<double>(delta))).normalized());
  }
  const vehicle_model::Pose pose = vehicle_model::pose(state, *state.find(key));
  const Eigen::VectorXd carried = vehicle_model::yawDirectionAt(pose, book.vehicleYawDirection());
  const Eigen::VectorXd truth = vehicle_model::yawDirection(pose, 9);
  EXPECT_LT((carried - truth).cwiseAbs().maxCoeff(), 1e-6)
      << "carried " << carried.transpose() << "\n true " << truth.transpose();
}

// A 25 m-radius turn at 10 m height, 3 m/s, noisy IMU with bias walks, 0.5 px pixel noise.
/// perturb: the initial estimate sampled from its uncertainty (every scenario's default).
std::string turnScenario(uint64_t seed, bool perturb = true) {
  return "name: oc_turn\nseed: " + std::to_string(seed) +
         "\nduration: 30.0\n"
         "world: {relief_amplitude: 1.0, landmark_density: 0.5, margin: 30.0}\n"
         "agents:\n"
         "  - id: 1\n"
         "    trajectory: {kind: circle, centre: [0.0, 0.0], radius: 25.0, altitude: 10.0, "
         "speed: 3.0, heading: velocity, tilt: bank}\n"
         "    initial_uncertainty: {position_sigma: [0.1, 0.1, 0.1], velocity_sigma: [0.05, "
         "0.05, 0.05], attitude_sigma_deg: [0.5, 0.5, " +
         std::to_string(kInitialYawSigmaDeg) + "], perturb: " + (perturb ? "true" : "false") +
         "}\n"
         "    camera_rate_hz: 10.0\n"
         "    pixel_noise: {kind: gaussian, sigma_px: 0.5}\n";
}

struct TurnStatistics {
  double min_yaw_sigma_deg = 1e9;
  double mean_pose_nees = 0.0;  ///< position + yaw (4 dof), over frames and seeds
};

TurnStatistics monteCarloTurns(bool observability_constrained,
                               vehicle::Attitude attitude = vehicle::Attitude::kEuler,
                               bool perturb = true, ErrorChart chart = ErrorChart::kAdditive) {
  VisualInertialSlamOptions o;
  o.ins.estimate_imu_bias = true;
  o.ins.attitude = attitude;
  o.map.k = 20;
  o.slam.error_chart = chart;
  o.slam.first_estimate_jacobians = chart == ErrorChart::kAdditive;
  o.slam.observability_constrained = observability_constrained;
  TurnStatistics out;
  int n = 0;
  for (uint64_t seed : {21u, 22u, 23u}) {
    auto sc = sim::Scenario::fromString(turnScenario(seed, perturb), "oc_turn.yaml");
    EXPECT_TRUE(sc.ok()) << sc.status().message();
    auto run = SimulatedTeamRun::create(*sc, o);
    EXPECT_TRUE(run.ok()) << run.status().message();
    if (!sc.ok() || !run.ok()) return out;
    const Status s = (*run)->run([&](const SimulatedFrame& f) {
      const Eigen::VectorXd x = f.slam->vehicleState();
      const Eigen::MatrixXd P = f.slam->vehicleCovariance();
      Eigen::Vector4d e;
      e.head<3>() = x.head<3>() - f.truth->p_BinN;
      e(3) = wrapAngle(x(vehicle::kAttitude + 2) - f.truth->euler(2));
      Eigen::Matrix4d P4;
      const int yaw = vehicle::kAttitude + 2;
      P4.topLeftCorner<3, 3>() = P.topLeftCorner<3, 3>();
      P4.topRightCorner<3, 1>() = P.block<3, 1>(0, yaw);
      P4.bottomLeftCorner<1, 3>() = P.block<1, 3>(yaw, 0);
      P4(3, 3) = P(yaw, yaw);
      out.mean_pose_nees += e.dot(P4.ldlt().solve(e));
      out.min_yaw_sigma_deg = std::min(out.min_yaw_sigma_deg, std::sqrt(P(yaw, yaw)) / kDegToRad);
      ++n;
      return Status::Ok();
    });
    EXPECT_TRUE(s.ok()) << s.message();
  }
  out.mean_pose_nees /= std::max(n, 1);
  return out;
}

TEST(ObservabilityConstraint, TurnsNeverGainAbsoluteYawAndStayConsistent) {
  const TurnStatistics oc = monteCarloTurns(true);
  RecordProperty("min_yaw_sigma_deg", std::to_string(oc.min_yaw_sigma_deg));
  RecordProperty("mean_pose_nees", std::to_string(oc.mean_pose_nees));
  // Nothing observes the absolute yaw (landmarks are unknown): its σ can only grow.
  EXPECT_GE(oc.min_yaw_sigma_deg, 0.999 * kInitialYawSigmaDeg);
  // The 3 runs' mean 4-dof pose NEES inside their χ² band ([1.47, 7.78]; measured 4.78).
  const test::NeesBand band = test::neesBand(4, 3);
  EXPECT_TRUE(band.contains(oc.mean_pose_nees))
      << "mean pose NEES " << oc.mean_pose_nees << ", band " << band.str();
  // The same runs unconstrained gain yaw information nothing provides (measured: σ down to
  // 0.33°): the constraint is what keeps it (their NEES, 6.6, is still inside the band over
  // 30 s).
  const TurnStatistics plain = monteCarloTurns(false);
  RecordProperty("unconstrained_min_yaw_sigma_deg", std::to_string(plain.min_yaw_sigma_deg));
  std::cout << "OC: min yaw sigma " << oc.min_yaw_sigma_deg << " deg, NEES " << oc.mean_pose_nees
            << "; unconstrained: " << plain.min_yaw_sigma_deg << " deg, NEES "
            << plain.mean_pose_nees << "\n";
  EXPECT_LT(plain.min_yaw_sigma_deg, 0.5 * kInitialYawSigmaDeg);
}

TEST(ObservabilityConstraint, ErrorStateTurnsKeepMostOfTheYawUnobservable) {
  // The Euler model keeps the yaw σ exactly (above): its ψ is the yaw generator in every chart.
  // The error state's generator R̂ᵀe3 turns with each update's reset R̂ ← R̂ Exp(δθ̂). With the
  // reset Jacobian J_r(δθ̂) on P (CovarianceHelper::correctMean) half of that turn is carried;
  // the OC kept the generator at the prior nominal, so the other half — second order, ½ δθ̂ ×
  // R̂ᵀe3 per update — still leaks: 1° → 0.91° over this 30 s turn (0.73° without J_r, and
  // 0.58° with its sign reversed). Closing that gap is open (docs/filter.md). Measured from the
  // truth, where the leak was found; from perturbed starts (the scenarios' default) it is
  // larger, 1° → 0.83° and NEES 8.9 (docs/filter.md "Consistency over seeds").
  const TurnStatistics oc = monteCarloTurns(true, vehicle::Attitude::kErrorState, false);
  RecordProperty("error_state_min_yaw_sigma_deg", std::to_string(oc.min_yaw_sigma_deg));
  std::cout << "error state, OC: min yaw sigma " << oc.min_yaw_sigma_deg << " deg, NEES "
            << oc.mean_pose_nees << "\n";
  EXPECT_GE(oc.min_yaw_sigma_deg, 0.9 * kInitialYawSigmaDeg);
  EXPECT_LT(oc.mean_pose_nees, 8.0);
}

TEST(InvariantErrorChart, TurnsNeverGainAbsoluteYawWithTheFiltersOwnJacobians) {
  // The right-invariant chart (slam_state.h) keeps the yaw unobservable by construction: no
  // first estimates, no constraint, every Jacobian at the current estimate, for both attitude
  // parametrisations. The additive chart without them gains yaw information on the same turns
  // (the test above: its σ falls below the initial 1°).
  for (vehicle::Attitude attitude : {vehicle::Attitude::kEuler, vehicle::Attitude::kErrorState}) {
    const TurnStatistics ri = monteCarloTurns(false, attitude, true, ErrorChart::kRightInvariant);
    std::cout << (attitude == vehicle::Attitude::kEuler ? "Euler" : "error state")
              << ", invariant chart: min yaw sigma " << ri.min_yaw_sigma_deg << " deg, NEES "
              << ri.mean_pose_nees << "\n";
    EXPECT_GE(ri.min_yaw_sigma_deg, 0.999 * kInitialYawSigmaDeg);
    // Inside the χ² band of the 3 runs' 4-dof pose NEES ([1.47, 7.78]; measured 4.65).
    EXPECT_TRUE(test::neesBand(4, 3).contains(ri.mean_pose_nees)) << ri.mean_pose_nees;
  }
  const TurnStatistics additive = monteCarloTurns(false, vehicle::Attitude::kEuler, true);
  EXPECT_LT(additive.min_yaw_sigma_deg, 0.99 * kInitialYawSigmaDeg);
}

/// Mean 9-dof vehicle NEES (position, body velocity, Euler angles) over the first `duration`
/// seconds of thesis_loop, over both UAVs and the seeds (before UAV1's loop closure at 200 s).
double thesisLoopNees(SlamOptions::OcProjection projection, double duration,
                      std::initializer_list<uint64_t> seeds) {
  VisualInertialSlamOptions o;
  o.ins.estimate_imu_bias = true;
  o.ins.attitude = vehicle::Attitude::kEuler;  // as measured in docs/filter.md
  o.slam.error_chart = ErrorChart::kAdditive;  // the constraint's chart, with first estimates
  o.slam.first_estimate_jacobians = true;
  o.slam.observability_constrained = true;
  o.slam.oc_projection = projection;
  double sum = 0.0;
  int n = 0;
  for (uint64_t seed : seeds) {
    auto sc = sim::Scenario::loadFile(std::string(CVSLAM_SOURCE_DIR) +
                                      "/config/scenarios/thesis_loop.yaml");
    EXPECT_TRUE(sc.ok()) << sc.status().message();
    if (!sc.ok()) return 0.0;
    sc->seed = seed;
    sc->duration = duration;
    // As measured in docs/filter.md: biases known exactly at the start. With them drawn (the
    // scenarios' default) this legacy chart's range-weighted NEES is 22 (unweighted 286).
    for (sim::AgentSpec& a : sc->agents) a.initial.perturb_biases = false;
    auto run = SimulatedTeamRun::create(*sc, o);
    EXPECT_TRUE(run.ok()) << run.status().message();
    if (!run.ok()) return 0.0;
    const Status s = (*run)->run([&](const SimulatedFrame& f) {
      const Eigen::VectorXd x = f.slam->vehicleState();
      const Eigen::MatrixXd P = f.slam->vehicleCovariance().topLeftCorner<9, 9>();
      Eigen::Matrix<double, 9, 1> e;
      e.head<3>() = x.head<3>() - f.truth->p_BinN;
      e.segment<3>(3) = x.segment<3>(vehicle::kVelocity) - f.truth->v_B;
      for (int i = 0; i < 3; ++i)
        e(6 + i) = wrapAngle(x(vehicle::kAttitude + i) - f.truth->euler(i));
      sum += e.dot(P.ldlt().solve(e));
      ++n;
      return Status::Ok();
    });
    EXPECT_TRUE(s.ok()) << s.message();
  }
  return sum / std::max(n, 1);
}

// The range-weighted constraint (the additive chart's default) against the unweighted one, on
// seeds other than those the default was chosen on (101-106, docs/filter.md): 150 s of
// thesis_loop, both UAVs, before any loop closure. Range-weighted, the mean 9-dof NEES stays
// under twice its dof (measured 16.7) and more than 3 times below the unweighted one's
// (196.8). It is not consistent: above the χ² band of the 6 runs, [5.93, 12.70] (and 22 with
// the biases drawn from their prior): the legacy chart, not the shipped one.
TEST(ObservabilityConstraint, RangeWeightedProjectionKeepsTheLongFlightNeesUnderTwiceItsDof) {
  const double weighted =
      thesisLoopNees(SlamOptions::OcProjection::kRangeWeighted, 150.0, {7, 8, 9});
  const double unweighted =
      thesisLoopNees(SlamOptions::OcProjection::kUnweighted, 150.0, {7, 8, 9});
  RecordProperty("nees_range_weighted", std::to_string(weighted));
  RecordProperty("nees_unweighted", std::to_string(unweighted));
  std::cout << "thesis_loop 150 s, seeds 7-9: mean vehicle NEES (9 dof) range-weighted " << weighted
            << ", unweighted " << unweighted << "\n";
  EXPECT_LT(weighted, 2.0 * 9.0);
  EXPECT_GT(unweighted, 3.0 * weighted);
}

}  // namespace
}  // namespace cvslam
