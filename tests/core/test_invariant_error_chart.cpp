// The right-invariant error chart (slam_state.h ErrorChart, CovarianceHelper::correctMean):
// an update that moves the mean must carry the unobservable yaw direction from the prior mean
// to the posterior one, so that observations which cannot see a global yaw add no information
// about it — the property the additive chart loses (Huang, Mourikis & Roumeliotis 2010).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <iostream>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/invariant_chart_transport.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/so3.h"

namespace cvslam {
namespace {

const VariableKey kVehicle = VariableKey::vehicle(1);
constexpr int kLandmarks = 3;
constexpr int kUpdates = 3;

/// Vehicle (15 states, yaw σ 0.5 rad) and three landmarks triangulated from it (so their
/// covariance shares the vehicle's yaw uncertainty along the global yaw direction).
SlamState makeState(vehicle::Attitude attitude, ErrorChart chart) {
  SlamState state;
  state.setErrorChart(chart);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(vehicle::kSizeWithBias);
  x.head<9>() << 12.0, -7.0, -10.0, 3.0, 0.2, 0.1, 0.05, -0.03, 0.8;
  Eigen::MatrixXd P = 0.05 * Eigen::MatrixXd::Identity(x.size(), x.size());
  P(vehicle::kAttitude + 2, vehicle::kAttitude + 2) = 0.25;
  EXPECT_TRUE(vehicle_model::addVehicle(state, kVehicle, x, P, attitude).ok());
  const Eigen::Vector3d offsets[kLandmarks] = {
      {8.0, 4.0, 9.0}, {5.0, -6.0, 11.0}, {14.0, 1.0, 8.0}};  // body frame
  for (int j = 0; j < kLandmarks; ++j) {
    const StateVariable& v = *state.find(kVehicle);
    const vehicle_model::Pose pose = vehicle_model::pose(state, v);
    const Eigen::Vector3d l = pose.p_BinN + pose.R_BtoN * offsets[j];
    // ∂l/∂x_v: identity on the position, ∂(R b)/∂a = −[R b]× M on the attitude.
    Eigen::MatrixXd dl_dv = Eigen::MatrixXd::Zero(3, v.size);
    dl_dv.block<3, 3>(0, vehicle::kPosition).setIdentity();
    dl_dv.block<3, 3>(0, vehicle::kAttitude) =
        -so3::skew<double>(Eigen::Vector3d(pose.R_BtoN * offsets[j])) *
        vehicle_model::navRotationPerAttitude(pose);
    EXPECT_TRUE(CovarianceHelper::augment(state, VariableKey::landmark(100 + j), l, kVehicle, dl_dv,
                                          Eigen::Matrix3d::Identity(),
                                          0.05 * Eigen::Matrix3d::Identity())
                    .ok());
  }
  return state;
}

/// The global yaw direction of the whole state at its mean.
Eigen::VectorXd yawDirection(const SlamState& state) {
  Eigen::VectorXd N = Eigen::VectorXd::Zero(state.size());
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind == VariableKey::Kind::kVehicle) {
      N.segment(v.index, v.size) =
          vehicle_model::yawDirection(vehicle_model::pose(state, v), v.size);
    } else {
      N.segment<3>(v.index) = Eigen::Vector3d::UnitZ().cross(state.value(v).head<3>());
    }
  }
  return N;
}

double informationAlong(const SlamState& state, const Eigen::VectorXd& N) {
  return N.dot(state.covariance().ldlt().solve(N));
}

/// Each landmark in the body frame, Rᵀ(l − p): invariant under a global yaw. H by central
/// differences on the stored entries (the error state's δθ is part of the pose).
Eigen::VectorXd predict(const SlamState& state) {
  const StateVariable& v = *state.find(kVehicle);
  const vehicle_model::Pose pose = vehicle_model::pose(state, v);
  Eigen::VectorXd h(3 * kLandmarks);
  for (int j = 0; j < kLandmarks; ++j) {
    const StateVariable& l = *state.find(VariableKey::landmark(100 + j));
    h.segment<3>(3 * j) = pose.R_BtoN.transpose() * (state.value(l) - pose.p_BinN);
  }
  return h;
}

/// The landmarks seen at z: residual z − h(at) and H = ∂h/∂x at `at`.
MeasurementBatch relativeObservations(const SlamState& at, const Eigen::VectorXd& z) {
  const int n = at.size();
  Eigen::MatrixXd H(3 * kLandmarks, n);
  constexpr double kStep = 1e-6;
  for (int i = 0; i < n; ++i) {
    SlamState plus = at, minus = at;
    for (const StateVariable& v : at.variables()) {
      if (i < v.index || i >= v.index + v.size) continue;
      Eigen::VectorXd x = at.value(v);
      x(i - v.index) += kStep;
      plus.setValue(v, x);
      x(i - v.index) -= 2.0 * kStep;
      minus.setValue(v, x);
    }
    H.col(i) = (predict(plus) - predict(minus)) / (2.0 * kStep);
  }
  MeasurementBatch batch;
  batch.reset(n, 3 * kLandmarks);
  const Eigen::VectorXd residual = z - predict(at);
  for (int j = 0; j < kLandmarks; ++j) {
    const int g =
        batch.addObservation(residual.segment<3>(3 * j), 1e-4 * Eigen::Matrix3d::Identity());
    batch.setJacobian(g, 0, H.middleRows<3>(3 * j));
  }
  return batch;
}

/// Observations that move the mean by decimetres: each landmark seen (0.4, −0.3, 0.25) m from
/// where the state predicts it.
MeasurementBatch relativeObservations(const SlamState& state) {
  return relativeObservations(
      state, predict(state) + Eigen::Vector3d(0.4, -0.3, 0.25).replicate(kLandmarks, 1));
}

TEST(InvariantErrorChart, UpdatesAddNoInformationAboutTheGlobalYaw) {
  for (vehicle::Attitude attitude : {vehicle::Attitude::kEuler, vehicle::Attitude::kErrorState}) {
    SCOPED_TRACE(attitude == vehicle::Attitude::kEuler ? "Euler" : "error state");
    double gained[2] = {0.0, 0.0};
    Eigen::VectorXd first_posterior_mean[2];
    for (ErrorChart chart : {ErrorChart::kAdditive, ErrorChart::kRightInvariant}) {
      SlamState state = makeState(attitude, chart);
      const double before = informationAlong(state, yawDirection(state));
      for (int k = 0; k < kUpdates; ++k) {  // each linearised at the mean the last one left
        const MeasurementBatch batch = relativeObservations(state);
        EXPECT_LT((batch.H() * yawDirection(state)).norm(), 1e-6);  // h cannot see the yaw
        ASSERT_TRUE(CovarianceHelper::update(state, batch, UpdatePolicy::ekf(), nullptr).ok());
        if (k == 0) first_posterior_mean[chart == ErrorChart::kAdditive ? 0 : 1] = state.mean();
      }
      const int c = chart == ErrorChart::kAdditive ? 0 : 1;
      gained[c] = informationAlong(state, yawDirection(state)) / before;
    }
    std::cout << "yaw information after / before: additive " << gained[0] << ", invariant "
              << gained[1] << "\n";
    EXPECT_NEAR(gained[1], 1.0, 1e-4);  // carried exactly to the new mean
    EXPECT_GT(gained[0], 3.0);          // the additive chart fabricates it
    // The chart changes the covariance after an update, never that update's mean.
    EXPECT_LT((first_posterior_mean[0] - first_posterior_mean[1]).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// A loop closure's iterated update linearises first at the vehicle moved by a rigid alignment,
// metres and degrees from the prior mean (loop_closer.h). Each iteration's Jacobian must then be
// taken against the prior's own coordinates (H(x_i) J_i, iterated_update.cpp): H(x_i) alone
// annihilates the yaw direction at x_i, not the prior's, and the update draws spurious yaw
// information from the prior's yaw uncertainty.
TEST(InvariantErrorChart, IteratedUpdatesAwayFromThePriorAddNoInformationAboutTheGlobalYaw) {
  for (vehicle::Attitude attitude : {vehicle::Attitude::kEuler, vehicle::Attitude::kErrorState}) {
    SCOPED_TRACE(attitude == vehicle::Attitude::kEuler ? "Euler" : "error state");
    double gained[2] = {0.0, 0.0};
    for (ErrorChart chart : {ErrorChart::kAdditive, ErrorChart::kRightInvariant}) {
      SlamState state = makeState(attitude, chart);
      const double before = informationAlong(state, yawDirection(state));
      const Eigen::VectorXd z =
          predict(state) + Eigen::Vector3d(0.6, -0.5, 0.3).replicate(kLandmarks, 1);
      SlamState start = state;  // the vehicle moved 3° in yaw and 2 m, the landmarks not
      const StateVariable& v = *start.find(kVehicle);
      vehicle_model::moveRigidly(
          start, v, vehicle_model::pose(start, v).p_BinN + Eigen::Vector3d(1.5, -1.2, 0.3), 0.05);
      const CovarianceHelper::Linearisation linearise = [&](const SlamState& at,
                                                            MeasurementBatch* batch) {
        *batch = relativeObservations(at, z);
        EXPECT_LT((batch->H() * yawDirection(at)).norm(), 1e-6);  // h cannot see the yaw
        return Status::Ok();
      };
      IteratedUpdateOptions options;
      options.max_iterations = 4;
      MeasurementBatch batch;
      UpdateReport report;
      ASSERT_TRUE(CovarianceHelper::iteratedUpdate(state, start, linearise, options,
                                                   UpdatePolicy::ekf(), &batch, &report)
                      .ok());
      SCOPED_TRACE(chart == ErrorChart::kAdditive ? "additive" : "invariant");
      EXPECT_GE(report.iterations, 2);
      if (chart == ErrorChart::kRightInvariant) {      // converged to what the landmarks say (the
        EXPECT_LT((predict(state) - z).norm(), 0.05);  // additive chart's yaw pull: 0.69 m off)
      }
      gained[chart == ErrorChart::kAdditive ? 0 : 1] =
          informationAlong(state, yawDirection(state)) / before;
    }
    std::cout << "iterated, yaw information after / before: additive " << gained[0]
              << ", invariant " << gained[1] << "\n";
    EXPECT_NEAR(gained[1], 1.0, 1e-3);
    EXPECT_GT(gained[0], 2.0);
  }
}

// In a joint state of several vehicles each landmark keeps the rotation error of the vehicle
// that mapped it (SlamState::landmarkAnchor), whoever observes it later: the chart's transport
// couples the landmark's rows to that vehicle's attitude columns, and the anchor follows the
// landmark through rekey (held and back) and leaves with it.
TEST(InvariantErrorChart, LandmarksKeepTheRotationErrorOfTheVehicleThatMappedThem) {
  SlamState state = makeState(vehicle::Attitude::kEuler, ErrorChart::kRightInvariant);
  const VariableKey other = VariableKey::vehicle(2);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(vehicle::kSizeWithBias);
  x.head<9>() << -5.0, 3.0, -8.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.2;
  ASSERT_TRUE(vehicle_model::addVehicle(state, other, x,
                                        0.05 * Eigen::MatrixXd::Identity(x.size(), x.size()),
                                        vehicle::Attitude::kEuler)
                  .ok());
  const VariableKey landmark = VariableKey::landmark(100);
  ASSERT_NE(state.landmarkAnchor(landmark), nullptr);
  EXPECT_EQ(*state.landmarkAnchor(landmark), kVehicle);
  // Move every mean; the transport with the other vehicle as the observer.
  SlamState moved = state;
  Eigen::VectorXd shift = Eigen::VectorXd::Constant(state.size(), 0.05);
  for (const StateVariable& v : state.variables()) {
    moved.setValue(v, state.value(v) + shift.segment(v.index, v.size));
  }
  const InvariantChartTransport J(state.mean(), InvariantChartTransport::vehiclePoses(state), moved,
                                  &other);
  Eigen::MatrixXd Jt = Eigen::MatrixXd::Identity(state.size(), state.size());
  J.multiplyByTransposeFromRight(Jt);  // I Jᵀ
  const int l = state.find(landmark)->index;
  const int own = state.find(kVehicle)->index + vehicle::kAttitude;
  const int observer = state.find(other)->index + vehicle::kAttitude;
  EXPECT_GT(Jt.block(own, l, 3, 3).norm(), 1e-3);      // J(l, own attitude) ≠ 0
  EXPECT_EQ(Jt.block(observer, l, 3, 3).norm(), 0.0);  // nothing from the observer's
  // Held and back: the same anchor; marginalised: gone.
  ASSERT_TRUE(CovarianceHelper::rekey(state, landmark, VariableKey::heldLandmark(100)).ok());
  ASSERT_NE(state.landmarkAnchor(VariableKey::heldLandmark(100)), nullptr);
  EXPECT_EQ(state.landmarkAnchor(landmark), nullptr);
  ASSERT_TRUE(CovarianceHelper::rekey(state, VariableKey::heldLandmark(100), landmark).ok());
  EXPECT_EQ(*state.landmarkAnchor(landmark), kVehicle);
  ASSERT_TRUE(CovarianceHelper::marginalize(state, landmark).ok());
  EXPECT_EQ(state.landmarkAnchor(landmark), nullptr);
  // An independent prior has no anchor: it takes the observer's.
  ASSERT_TRUE(CovarianceHelper::addVariable(state, landmark, Eigen::Vector3d(1.0, 2.0, 3.0),
                                            Eigen::Matrix3d::Identity())
                  .ok());
  EXPECT_EQ(state.landmarkAnchor(landmark), nullptr);
}

}  // namespace
}  // namespace cvslam
