#include "cvslam/slam/ci_updater.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/measurement_batch.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/slam/loop_closer.h"

namespace cvslam {

Expected<CiChoice> CiUpdater::choose(const SlamState& state, const CiPeerEstimates& peer,
                                     const CiWeighting& weighting) const {
  const auto n = static_cast<Eigen::Index>(peer.ids.size());
  // Joint prior covariance of [vehicle; landmarks]: P1 is the landmarks' block, the vehicle
  // position blocks serve optimal_vehicle and the gain check.
  std::vector<VariableKey> joint_keys{vehicle_};
  for (int64_t id : peer.ids)
    joint_keys.push_back(VariableKey::landmark(static_cast<uint64_t>(id)));
  Expected<Eigen::MatrixXd> J = CovarianceHelper::marginalCovariance(state, joint_keys);
  if (!J.ok()) return J.status();
  const Eigen::Index nv = J.value().rows() - 3 * n;
  const Eigen::MatrixXd P1 = J.value().bottomRightCorner(3 * n, 3 * n);
  const Eigen::MatrixXd P_pp = J.value().topLeftCorner(3, 3);
  const Eigen::MatrixXd P_pL = J.value().block(0, nv, 3, 3 * n);
  const Eigen::MatrixXd& R = peer.R;
  const double own_trace = P1.trace();
  const double own_vehicle = P_pp.trace();
  CiChoice out;
  out.own_vehicle_trace = own_vehicle;
  if (weighting.independent) {
    // The EKF update: P_pp − P_pL (P_LL + R)⁻¹ P_Lp.
    out.omega1 = 1.0;
    out.vehicle_gain = (P_pL * (P1 + R).ldlt().solve(P_pL.transpose())).trace() > 0.0;
    return out;
  }
  // The weights read the covariance the update fuses, R (not the marginals it may bound).
  const double peer_trace = R.trace();
  double w = 1.0;
  const double nn = static_cast<double>(n);
  switch (weighting.method) {
    case CiMethod::kAdaptive:  // eq. 6.5 with per-landmark mean traces
      w = (peer_trace / nn + peer.vehicle_trace) /
          (own_trace / nn + peer_trace / nn + own_vehicle + peer.vehicle_trace);
      break;
    case CiMethod::kFast:  // eq. 6.4
      w = peer_trace / (own_trace + peer_trace);
      break;
    case CiMethod::kOptimalTrace:
    case CiMethod::kOptimalDeterminant:
      w = optimalCiOmega(P1, R, weighting.method == CiMethod::kOptimalDeterminant);
      break;
    case CiMethod::kOptimalVehicle:
      w = optimalVehicleCiOmega(P_pp, P_pL, P1, R, weighting.min_omega);
      break;
  }
  out.omega1 = std::clamp(w, weighting.min_omega, 1.0);
  // CI on the joint state inflates everything by 1/ω1; when the peer's landmarks would not even
  // shrink the bound on the vehicle position, fusing only loses information.
  out.vehicle_gain =
      out.omega1 < 1.0 && jointCiVehiclePositionTrace(P_pp, P_pL, P1, R, out.omega1) < own_vehicle;
  return out;
}

Status CiUpdater::apply(SlamState& state, LandmarkBook& book, const std::vector<int64_t>& ids,
                        const Eigen::VectorXd& y, const Eigen::MatrixXd& R, double omega1) const {
  if (!std::isfinite(omega1) || omega1 <= 0.0 || omega1 > 1.0)
    return Status::Error("CI fusion: omega1 must be in (0, 1]");
  // ω1 = 1 gives all the weight to the local estimate: nothing changes (eq. 6.2).
  if (omega1 >= 1.0) return validate(state, ids, y, R).status();
  // P⁻¹ ← ω1 P⁻¹ + ω2 Hᵀ R⁻¹ H  ⇔  scale the prior by 1/ω1, then an EKF update with R/ω2
  // (docs/cooperation.md).
  return update(state, book, ids, y, R, 1.0 / omega1, 1.0 / (1.0 - omega1));
}

Status CiUpdater::applyIndependent(SlamState& state, LandmarkBook& book,
                                   const std::vector<int64_t>& ids, const Eigen::VectorXd& y,
                                   const Eigen::MatrixXd& R) const {
  // Independent estimates: information adds, P⁻¹ ← P⁻¹ + Hᵀ R⁻¹ H, the plain EKF update.
  return update(state, book, ids, y, R, 1.0, 1.0);
}

Expected<std::vector<const StateVariable*>> CiUpdater::validate(const SlamState& state,
                                                                const std::vector<int64_t>& ids,
                                                                const Eigen::VectorXd& y,
                                                                const Eigen::MatrixXd& R) const {
  const auto m = static_cast<Eigen::Index>(ids.size());
  if (y.size() != 3 * m || R.rows() != 3 * m || R.cols() != 3 * m)
    return Status::Error("CI fusion: y and R must have 3 rows per landmark");
  if (!y.allFinite() || !R.allFinite()) return Status::Error("CI fusion: non-finite peer estimate");
  std::vector<const StateVariable*> vars;
  for (int64_t id : ids) {
    const StateVariable* v = state.find(VariableKey::landmark(static_cast<uint64_t>(id)));
    if (v == nullptr)
      return Status::Error("CI fusion: landmark " + std::to_string(id) + " is not in the state");
    vars.push_back(v);
  }
  return vars;
}

Status CiUpdater::update(SlamState& state, LandmarkBook& book, const std::vector<int64_t>& ids,
                         const Eigen::VectorXd& y, const Eigen::MatrixXd& R, double prior_scale,
                         double r_scale) const {
  const auto m = static_cast<Eigen::Index>(ids.size());
  Expected<std::vector<const StateVariable*>> checked = validate(state, ids, y, R);
  if (!checked.ok()) return checked.status();
  if (m == 0) return Status::Ok();
  const std::vector<const StateVariable*>& vars = checked.value();
  // H selects the landmarks, the residual is y − p_L.
  Eigen::VectorXd r(3 * m);
  for (Eigen::Index i = 0; i < m; ++i)
    r.segment<3>(3 * i) = y.segment<3>(3 * i) - state.value(*vars[static_cast<size_t>(i)]);
  if (prior_scale != 1.0) {
    // CI bounds the joint covariance of everything whose correlation with the peer is unknown:
    // the vehicle, its landmarks AND its held (Schmidt) landmarks. Scaling only the active part
    // (rows by 1/ω1, the held–active cross-covariance by 1/√ω1, the held block not at all) is no
    // bound once the held landmarks correlate with the peer's estimates: for a direction
    // [0; t·u; w] the bound's excess over the truth is linear in t and turns negative. The held
    // landmarks of a per-agent state are all this vehicle's.
    std::vector<VariableKey> scaled = book.variablesIn(state, vehicle_);
    for (const StateVariable& v : state.variables())
      if (v.key.kind == VariableKey::Kind::kHeldLandmark) scaled.push_back(v.key);
    if (Status s = CovarianceHelper::scaleCovariance(state, scaled, prior_scale); !s.ok()) return s;
  }
  MeasurementBatch batch;
  batch.reset(state.size(), static_cast<int>(3 * m));
  const int g = batch.addObservation(r, r_scale * R);
  for (Eigen::Index i = 0; i < m; ++i) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3 * m, 3);
    H.block<3, 3>(3 * i, 0).setIdentity();
    batch.setJacobian(g, *vars[static_cast<size_t>(i)], H);
  }
  const Eigen::VectorXd mean_before = state.mean();
  UpdateReport report;
  if (Status s = CovarianceHelper::update(state, batch, UpdatePolicy::ekf(), &report); !s.ok())
    return s;
  // The peer's landmarks can move the vehicle and, through it, the whole local map by far more
  // than the stereo updates do (metres when a drifted UAV meets an accurate one). First-
  // estimates Jacobians linearised at the old positions would then pair the new vehicle with
  // the old map; they follow the correction, as after a loop closure (loop_closer.h).
  followCorrection(state, mean_before, vehicle_, &book);
  return Status::Ok();
}

}  // namespace cvslam
