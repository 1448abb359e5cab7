#include "cvslam/filter/vehicle_model.h"

#include <cmath>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/geometry/so3.h"

namespace cvslam::vehicle_model {
namespace {

/// W(φ, θ): body rates from Euler rates (inverse of E of eq. 2.4), so that
/// R(e + de) = R(e) Exp(W de): ∂δθ/∂e.
Eigen::Matrix3d errorPerEuler(const Eigen::Vector3d& e) {
  const double sr = std::sin(e(0)), cr = std::cos(e(0));
  const double sp = std::sin(e(1)), cp = std::cos(e(1));
  Eigen::Matrix3d W;
  W << 1.0, 0.0, -sp, 0.0, cr, sr * cp, 0.0, -sr, cr * cp;
  return W;
}

/// E(φ, θ) of eq. 2.4: ∂e/∂δθ. cos θ is kept away from zero so that a vehicle at pitch ±90°
/// reports large variances of φ and ψ rather than infinite ones.
Eigen::Matrix3d eulerPerError(const Eigen::Vector3d& e) {
  constexpr double kMinCosPitch = 1e-6;
  const double sr = std::sin(e(0)), cr = std::cos(e(0));
  double cp = std::cos(e(1));
  if (std::abs(cp) < kMinCosPitch) cp = std::copysign(kMinCosPitch, cp);
  const double tp = std::sin(e(1)) / cp;
  Eigen::Matrix3d E;
  E << 1.0, sr * tp, cr * tp, 0.0, cr, -sr, 0.0, sr / cp, cr / cp;
  return E;
}

/// Identity with `attitude_block` on the attitude rows and columns (size n).
Eigen::MatrixXd attitudeMap(int n, const Eigen::Matrix3d& attitude_block) {
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(n, n);
  T.block<3, 3>(vehicle::kAttitude, vehicle::kAttitude) = attitude_block;
  return T;
}

}  // namespace

Pose pose(const SlamState& state, const StateVariable& vehicle) {
  const Eigen::Matrix<double, kPoseSize, 1> x = state.value(vehicle).head<kPoseSize>();
  const Eigen::Quaterniond* nominal = state.nominalAttitude(vehicle.key);
  if (nominal == nullptr) return Pose::fromEuler(x);
  Pose p;
  p.p_BinN = x.segment<3>(vehicle::kPosition);
  p.v_B = x.segment<3>(vehicle::kVelocity);
  // δθ is zero between updates; a non-zero one (mid-update) is part of the pose.
  p.R_BtoN = nominal->toRotationMatrix() * so3::exp<double>(x.segment<3>(vehicle::kAttitude));
  p.attitude = vehicle::Attitude::kErrorState;
  return p;
}

vehicle::Attitude attitudeOf(const SlamState& state, const VariableKey& vehicle) {
  return state.nominalAttitude(vehicle) != nullptr ? vehicle::Attitude::kErrorState
                                                   : vehicle::Attitude::kEuler;
}

Eigen::Quaterniond nominalAttitude(const SlamState& state, const VariableKey& vehicle) {
  const Eigen::Quaterniond* nominal = state.nominalAttitude(vehicle);
  return nominal != nullptr ? *nominal : Eigen::Quaterniond::Identity();
}

void setNominalAttitude(SlamState& state, const VariableKey& vehicle,
                        const Eigen::Quaterniond& q_BtoN) {
  if (state.nominalAttitude(vehicle) != nullptr) state.setNominalAttitude(vehicle, q_BtoN);
}

Status addVehicle(SlamState& state, const VariableKey& vehicle, const Eigen::VectorXd& x_euler,
                  const Eigen::MatrixXd& P_euler, vehicle::Attitude attitude) {
  if (attitude == vehicle::Attitude::kEuler || x_euler.size() < vehicle::kSizeNoBias) {
    return CovarianceHelper::addVariable(state, vehicle, x_euler, P_euler);
  }
  const Eigen::Vector3d e = x_euler.segment<3>(vehicle::kAttitude);
  const Eigen::MatrixXd T = attitudeMap(static_cast<int>(x_euler.size()), errorPerEuler(e));
  return addVehicle(state, vehicle, x_euler, Eigen::Quaterniond(rotationBodyToNav(e)),
                    T * P_euler * T.transpose());
}

Status addVehicle(SlamState& state, const VariableKey& vehicle, const Eigen::VectorXd& x_v,
                  const Eigen::Quaterniond& q_BtoN, const Eigen::MatrixXd& P_v) {
  Eigen::VectorXd x = x_v;
  if (x.size() >= vehicle::kSizeNoBias) x.segment<3>(vehicle::kAttitude).setZero();
  if (Status s = CovarianceHelper::addVariable(state, vehicle, x, P_v); !s.ok()) return s;
  state.setNominalAttitude(vehicle, q_BtoN.normalized());
  return Status::Ok();
}

Eigen::Matrix3d errorCovarianceFromNav(const Eigen::Quaterniond& q_BtoN,
                                       const Eigen::Matrix3d& P_N) {
  const Eigen::Matrix3d R = q_BtoN.toRotationMatrix();
  return R.transpose() * P_N * R;
}

void eulerLayout(const SlamState& state, const StateVariable& vehicle, Eigen::VectorXd* x,
                 Eigen::MatrixXd* P) {
  *x = state.value(vehicle);
  *P = state.covarianceOf(vehicle);
  if (state.nominalAttitude(vehicle.key) == nullptr) return;
  const Eigen::Vector3d e = eulerFromRotationNavToBody(pose(state, vehicle).R_BtoN.transpose());
  x->segment<3>(vehicle::kAttitude) = e;
  const Eigen::MatrixXd T = attitudeMap(vehicle.size, eulerPerError(e));
  *P = T * *P * T.transpose();
}

void setPoseJacobian(MeasurementBatch& batch, int group, const StateVariable& vehicle,
                     const Eigen::Matrix<double, 4, kPoseSize>& dz_dpose) {
  // The pose is the head of the block: its Jacobian is the block's first kPoseSize columns.
  batch.setJacobian(group, vehicle.index, dz_dpose);
}

void poseToBlockJacobian(const Eigen::Matrix<double, 3, kPoseSize>& dy_dpose,
                         Eigen::MatrixXd* dy_dblock) {
  dy_dblock->leftCols<kPoseSize>() = dy_dpose;
}

void correct(Eigen::Ref<Eigen::VectorXd> x_v, const Eigen::Ref<const Eigen::VectorXd>& dx_v,
             Eigen::Quaterniond* nominal) {
  x_v += dx_v;
  if (x_v.size() < vehicle::kSizeNoBias) return;
  if (nominal != nullptr) {
    // Reset: R̂ ← R̂ Exp(δθ), δθ ← 0 (reset Jacobian taken as I, see the header).
    const Eigen::Vector3d d = x_v.segment<3>(vehicle::kAttitude);
    *nominal = (*nominal * Eigen::Quaterniond(so3::exp<double>(d))).normalized();
    x_v.segment<3>(vehicle::kAttitude).setZero();
    return;
  }
  x_v(vehicle::kAttitude) = wrapAngle(x_v(vehicle::kAttitude));
  x_v(vehicle::kAttitude + 2) = wrapAngle(x_v(vehicle::kAttitude + 2));
}

Eigen::VectorXd difference(const Eigen::Ref<const Eigen::VectorXd>& x_a,
                           const Eigen::Quaterniond* nominal_a,
                           const Eigen::Ref<const Eigen::VectorXd>& x_b,
                           const Eigen::Quaterniond* nominal_b) {
  Eigen::VectorXd d = x_a - x_b;
  if (d.size() < vehicle::kSizeNoBias) return d;
  if (nominal_a != nullptr && nominal_b != nullptr) {
    // R_a = R_b Exp(δθ) (right perturbation, as `correct` folds it): δθ = Log(R_bᵀ R_a), plus
    // any unfolded δθ_a − δθ_b (first order).
    d.segment<3>(vehicle::kAttitude) +=
        so3::log((nominal_b->conjugate() * *nominal_a).toRotationMatrix());
    return d;
  }
  d(vehicle::kAttitude) = wrapAngle(d(vehicle::kAttitude));
  d(vehicle::kAttitude + 2) = wrapAngle(d(vehicle::kAttitude + 2));
  return d;
}

void moveRigidly(SlamState& state, const StateVariable& vehicle, const Eigen::Vector3d& position,
                 double delta_yaw) {
  Eigen::VectorXd x_v = state.value(vehicle);
  x_v.segment<3>(vehicle::kPosition) = position;
  if (const Eigen::Quaterniond* nominal = state.nominalAttitude(vehicle.key)) {
    // A heading change about N's z acts on the left: R ← Rz(Δψ) R (δθ, in B, unchanged).
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(delta_yaw, Eigen::Vector3d::UnitZ()));
    state.setNominalAttitude(vehicle.key, (turn * *nominal).normalized());
  } else {
    x_v(vehicle::kAttitude + 2) = wrapAngle(x_v(vehicle::kAttitude + 2) + delta_yaw);
  }
  state.setValue(vehicle, x_v);
}

Eigen::Matrix3d navRotationPerAttitude(const Pose& pose) {
  // R(e + de) = R(e) Exp(W de) = Exp(R(e) W de) R(e); R̂ Exp(δθ) = Exp(R̂ δθ) R̂.
  if (pose.attitude == vehicle::Attitude::kEuler) return pose.R_BtoN * errorPerEuler(pose.euler);
  return pose.R_BtoN;
}

Eigen::VectorXd yawDirection(const Pose& pose, int block_size) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(block_size);
  const Eigen::Vector3d& p = pose.p_BinN;
  u.segment<3>(vehicle::kPosition) = Eigen::Vector3d(-p.y(), p.x(), 0.0);  // e3 × p
  if (pose.attitude == vehicle::Attitude::kEuler) {
    u(vehicle::kAttitude + 2) = 1.0;  // ZYX Euler: a rotation about N's z adds to ψ only
  } else {
    u.segment<3>(vehicle::kAttitude) = pose.R_BtoN.transpose().col(2);  // R̂ᵀ e3
  }
  return u;
}

Eigen::VectorXd yawDirectionAt(const Pose& pose, const Eigen::VectorXd& u_v) {
  if (pose.attitude == vehicle::Attitude::kEuler) return u_v;
  Eigen::VectorXd u = u_v;
  u.segment<3>(vehicle::kAttitude) = pose.R_BtoN.transpose().col(2);  // R̂ᵀ e3
  return u;
}

}  // namespace cvslam::vehicle_model
