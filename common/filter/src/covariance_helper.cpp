// CovarianceHelper: variables in and out, marginals, propagation. The measurement update is
// in covariance_update.cpp.
#include "cvslam/filter/covariance_helper.h"

#include <cmath>
#include <string>

#include "cvslam/filter/invariant_chart_transport.h"
#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {
namespace {

std::string describe(const VariableKey& key) {
  const char* kind = key.kind == VariableKey::Kind::kVehicle    ? "vehicle "
                     : key.kind == VariableKey::Kind::kLandmark ? "landmark "
                                                                : "held landmark ";
  return kind + std::to_string(key.id);
}

/// Symmetrises in place: the updates are symmetric in exact arithmetic only.
void symmetrize(Eigen::MatrixXd& P) {
  P = 0.5 * (P + P.transpose()).eval();
}

}  // namespace

Status CovarianceHelper::append(SlamState& state, const VariableKey& key,
                                const Eigen::VectorXd& value) {
  if (state.has(key)) return Status::Error(describe(key) + " is already in the state");
  if (value.size() == 0) return Status::Error("cannot add an empty variable");
  const int n = state.size(), k = static_cast<int>(value.size());
  state.x_.conservativeResize(n + k);
  state.x_.tail(k) = value;
  state.P_.conservativeResize(n + k, n + k);
  state.slot_[key] = static_cast<int>(state.vars_.size());
  state.vars_.push_back({key, n, k});
  return Status::Ok();
}

Status CovarianceHelper::addVariable(SlamState& state, const VariableKey& key,
                                     const Eigen::VectorXd& value,
                                     const Eigen::MatrixXd& covariance) {
  const int k = static_cast<int>(value.size());
  if (covariance.rows() != k || covariance.cols() != k) {
    return Status::Error("covariance of " + describe(key) + " does not match its size");
  }
  if (Status s = append(state, key, value); !s.ok()) return s;
  state.P_.bottomRows(k).setZero();
  state.P_.rightCols(k).setZero();
  state.P_.bottomRightCorner(k, k) = 0.5 * (covariance + covariance.transpose());
  return Status::Ok();
}

Status CovarianceHelper::augment(SlamState& state, const VariableKey& key,
                                 const Eigen::VectorXd& value, const Eigen::MatrixXd& dy_dx,
                                 const Eigen::MatrixXd& dy_dz, const Eigen::MatrixXd& R_z) {
  const int n = state.size(), k = static_cast<int>(value.size());
  if (dy_dx.rows() != k || dy_dx.cols() != n || dy_dz.rows() != k || dy_dz.cols() != R_z.rows() ||
      R_z.rows() != R_z.cols()) {
    return Status::Error("augment: Jacobian sizes do not match the state or the noise");
  }
  // P_yx = J_x P must be formed before the state grows.
  const Eigen::MatrixXd P_yx = dy_dx * state.P_;
  Eigen::MatrixXd P_yy = P_yx * dy_dx.transpose() + dy_dz * R_z * dy_dz.transpose();
  symmetrize(P_yy);
  if (Status s = append(state, key, value); !s.ok()) return s;
  state.P_.bottomLeftCorner(k, n) = P_yx;
  state.P_.topRightCorner(n, k) = P_yx.transpose();
  state.P_.bottomRightCorner(k, k) = P_yy;
  return Status::Ok();
}

Status CovarianceHelper::augment(SlamState& state, const VariableKey& key,
                                 const Eigen::VectorXd& value, const VariableKey& source,
                                 const Eigen::MatrixXd& dy_dsource, const Eigen::MatrixXd& dy_dz,
                                 const Eigen::MatrixXd& R_z) {
  const StateVariable* src = state.find(source);
  if (src == nullptr) return Status::Error("augment: " + describe(source) + " is not in the state");
  const int n = state.size(), k = static_cast<int>(value.size());
  if (dy_dsource.rows() != k || dy_dsource.cols() != src->size || dy_dz.rows() != k ||
      dy_dz.cols() != R_z.rows() || R_z.rows() != R_z.cols()) {
    return Status::Error("augment: Jacobian sizes do not match the source or the noise");
  }
  // Only the source's rows of P enter: P_yx = J_s P_s·, P_yy = J_s P_ss J_sᵀ + J_z R J_zᵀ.
  const Eigen::MatrixXd P_yx = dy_dsource * state.P_.middleRows(src->index, src->size);
  Eigen::MatrixXd P_yy = P_yx.middleCols(src->index, src->size) * dy_dsource.transpose() +
                         dy_dz * R_z * dy_dz.transpose();
  symmetrize(P_yy);
  if (Status s = append(state, key, value); !s.ok()) return s;
  state.P_.bottomLeftCorner(k, n) = P_yx;
  state.P_.topRightCorner(n, k) = P_yx.transpose();
  state.P_.bottomRightCorner(k, k) = P_yy;
  if (source.kind == VariableKey::Kind::kVehicle) state.anchor_[key] = source;
  return Status::Ok();
}

Status CovarianceHelper::marginalize(SlamState& state, const VariableKey& key) {
  const auto it = state.slot_.find(key);
  if (it == state.slot_.end()) return Status::Error(describe(key) + " is not in the state");
  const std::size_t pos = static_cast<std::size_t>(it->second);
  const StateVariable removed = state.vars_[pos];
  const int n = state.size();
  std::vector<int> keep;
  keep.reserve(static_cast<std::size_t>(n - removed.size));
  for (int i = 0; i < n; ++i) {
    if (i < removed.index || i >= removed.index + removed.size) keep.push_back(i);
  }
  state.x_ = state.x_(keep).eval();
  state.P_ = state.P_(keep, keep).eval();
  state.vars_.erase(state.vars_.begin() + static_cast<std::ptrdiff_t>(pos));
  state.slot_.erase(it);
  state.nominal_.erase(key);
  state.anchor_.erase(key);
  for (std::size_t j = pos; j < state.vars_.size(); ++j) {
    state.vars_[j].index -= removed.size;
    state.slot_[state.vars_[j].key] = static_cast<int>(j);
  }
  return Status::Ok();
}

Status CovarianceHelper::rekey(SlamState& state, const VariableKey& from, const VariableKey& to) {
  const auto it = state.slot_.find(from);
  if (it == state.slot_.end()) return Status::Error(describe(from) + " is not in the state");
  if (state.has(to)) return Status::Error(describe(to) + " is already in the state");
  const int pos = it->second;
  state.slot_.erase(it);
  state.slot_[to] = pos;
  state.vars_[static_cast<std::size_t>(pos)].key = to;
  if (const auto a = state.anchor_.find(from); a != state.anchor_.end()) {
    const VariableKey anchor = a->second;
    state.anchor_.erase(a);
    state.anchor_[to] = anchor;
  }
  return Status::Ok();
}

Expected<Eigen::MatrixXd> CovarianceHelper::marginalCovariance(
    const SlamState& state, const std::vector<VariableKey>& keys) {
  std::vector<const StateVariable*> vars;
  int total = 0;
  for (const VariableKey& key : keys) {
    const StateVariable* v = state.find(key);
    if (v == nullptr) return Status::Error(describe(key) + " is not in the state");
    vars.push_back(v);
    total += v->size;
  }
  Eigen::MatrixXd out(total, total);
  int r = 0;
  for (const StateVariable* a : vars) {
    int c = 0;
    for (const StateVariable* b : vars) {
      out.block(r, c, a->size, b->size) = state.P_.block(a->index, b->index, a->size, b->size);
      c += b->size;
    }
    r += a->size;
  }
  return out;
}

Status CovarianceHelper::propagate(SlamState& state, const VariableKey& vehicle,
                                   const Eigen::VectorXd& value, const Eigen::MatrixXd& Phi,
                                   const Eigen::MatrixXd& Qd, const UpdatePolicy& policy) {
  const StateVariable* v = state.find(vehicle);
  if (v == nullptr)
    return Status::Error("propagate: " + describe(vehicle) + " is not in the state");
  const int i = v->index, k = v->size;
  if (value.size() != k || Phi.rows() != k || Phi.cols() != k || Qd.rows() != k || Qd.cols() != k) {
    return Status::Error("propagate: sizes do not match " + describe(vehicle));
  }
  // Rows of the vehicle: [Φ P_vv, Φ P_vo]; the vehicle block then gets Φ P_vv Φᵀ + c_w² Q.
  const Eigen::MatrixXd rows = Phi * state.P_.middleRows(i, k);
  Eigen::MatrixXd P_vv = rows.middleCols(i, k) * Phi.transpose() + policy.process_noise_scale * Qd;
  symmetrize(P_vv);
  state.P_.middleRows(i, k) = rows;
  state.P_.middleCols(i, k) = rows.transpose();
  state.P_.block(i, i, k, k) = P_vv;
  state.x_.segment(i, k) = value;
  return Status::Ok();
}

Status CovarianceHelper::scaleCovariance(SlamState& state, double factor) {
  if (!(factor > 0.0)) return Status::Error("scaleCovariance: factor must be > 0");
  state.P_ *= factor;
  return Status::Ok();
}

Status CovarianceHelper::scaleCovariance(SlamState& state, const std::vector<VariableKey>& keys,
                                         double factor) {
  if (!(factor > 0.0)) return Status::Error("scaleCovariance: factor must be > 0");
  std::vector<bool> scaled(static_cast<std::size_t>(state.size()), false);
  for (const VariableKey& key : keys) {
    const StateVariable* v = state.find(key);
    if (v == nullptr)
      return Status::Error("scaleCovariance: " + describe(key) + " is not in the state");
    for (int i = v->index; i < v->index + v->size; ++i) scaled[static_cast<std::size_t>(i)] = true;
  }
  const double root = std::sqrt(factor);
  for (int j = 0; j < state.size(); ++j) {
    const bool sj = scaled[static_cast<std::size_t>(j)];
    for (int i = 0; i < state.size(); ++i) {
      const bool si = scaled[static_cast<std::size_t>(i)];
      if (si && sj) {
        state.P_(i, j) *= factor;
      } else if (si || sj) {
        state.P_(i, j) *= root;
      }
    }
  }
  return Status::Ok();
}

void CovarianceHelper::correctMean(SlamState& state, const Eigen::VectorXd& dx,
                                   const VariableKey* anchor) {
  const bool invariant = state.chart_ == ErrorChart::kRightInvariant;
  Eigen::VectorXd x_prior;
  std::vector<vehicle_model::Pose> prior_poses;  // per vehicle, in index order
  if (invariant) {
    x_prior = state.x_;
    prior_poses = InvariantChartTransport::vehiclePoses(state);
  }
  for (const StateVariable& v : state.vars_) {
    auto x = state.x_.segment(v.index, v.size);
    const auto d = dx.segment(v.index, v.size);
    if (v.key.kind == VariableKey::Kind::kVehicle) {
      // The vehicle block's own correction: angles wrapped, or δθ folded into the nominal.
      const auto nominal = state.nominal_.find(v.key);
      if (nominal != state.nominal_.end() && !invariant) {
        // The reset R̂ ← R̂ Exp(δθ̂) moves the error-state chart: the error in the new chart is
        // J_r(δθ̂) times the old one, so P's attitude rows and columns are mapped by it. Taken
        // as I, every update leaked global-yaw information the observability constraint had
        // kept out (ObservabilityConstraint.ErrorStateTurns…: yaw σ 1° → 0.73° on a turn).
        // (The invariant chart's reset, below, includes it.)
        const int a = v.index + vehicle::kAttitude;
        const Eigen::Matrix3d G =
            so3::rightJacobian<double>(Eigen::Vector3d(d.segment<3>(vehicle::kAttitude)));
        state.P_.middleRows(a, 3) = (G * state.P_.middleRows(a, 3)).eval();
        state.P_.middleCols(a, 3) = (state.P_.middleCols(a, 3) * G.transpose()).eval();
      }
      vehicle_model::correct(x, d, nominal == state.nominal_.end() ? nullptr : &nominal->second);
    } else {
      x += d;
    }
  }
  if (!invariant) return;
  // The update kept the covariance of the invariant error ξ = A(x̂⁻) δ (slam_state.h); in the
  // stored coordinates at the corrected mean that is J δ (invariant_chart_transport.h), so
  // P ← J P Jᵀ. A landmark's rotation error is that of the vehicle it was mapped from
  // (SlamState::landmarkAnchor), else the observing vehicle's (`anchor`); any vehicle's keeps
  // the global yaw direction, which they share.
  const InvariantChartTransport J(x_prior, prior_poses, state, anchor);
  // P Jᵀ by columns, then J (P Jᵀ) by rows: symmetric up to rounding (the next update mirrors
  // what it changes). Two transposes of P cost more than this (held landmarks make n large).
  J.multiplyByTransposeFromRight(state.P_);
  J.multiplyFromLeft(state.P_);
}

}  // namespace cvslam
