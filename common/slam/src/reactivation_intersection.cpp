#include "cvslam/slam/reactivation_intersection.h"

#include <algorithm>
#include <limits>
#include <utility>

#include <Eigen/Cholesky>

#include "cvslam/core/golden_section.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/landmark_lifecycle.h"

namespace cvslam {

namespace {

/// The pieces of the split-prior update that do not depend on ω. With H = [H_A H_B] and the
/// prior blockdiag(P_A/ω, n·P_B/(1 − ω)) (n landmarks in B), the innovation covariance is
/// S_A/ω + S_B/(1 − ω) + R with S_B = n·H_B P_B H_Bᵀ, and the rows V of P H̃ᵀ are G_V/ω, so the
/// posterior covariance of V is P_VV/ω − G_V S⁻¹ G_Vᵀ/ω² (V: the position rows of every
/// vehicle of the objective, or their whole blocks).
struct SplitUpdate {
  Eigen::MatrixXd S_A, S_B, R, G, P_pp, G_V, P_VV;

  Eigen::MatrixXd innovation(double omega) const { return S_A / omega + S_B / (1.0 - omega) + R; }
  double positionTrace(double omega) const {
    const Eigen::MatrixXd S = innovation(omega);
    return P_pp.trace() / omega - (G * S.ldlt().solve(G.transpose())).trace() / (omega * omega);
  }
  /// log det of the vehicles' blocks after the update; +∞ when not positive definite.
  double vehicleLogDet(double omega) const {
    const Eigen::MatrixXd S = innovation(omega);
    return logDet(P_VV / omega - G_V * S.ldlt().solve(G_V.transpose()) / (omega * omega));
  }
  static double logDet(const Eigen::MatrixXd& M) {
    const Eigen::LLT<Eigen::MatrixXd> llt(M);
    if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
    return 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  }
};

/// The rows `blocks` (first index, size) of P: their products with H_Aᵀ and their covariance.
void gatherRows(const Eigen::MatrixXd& P, const Eigen::MatrixXd& H_A,
                const std::vector<std::pair<int, int>>& blocks, Eigen::MatrixXd* G,
                Eigen::MatrixXd* P_rr) {
  std::vector<Eigen::Index> rows;
  for (const auto& [first, size] : blocks)
    for (int k = 0; k < size; ++k) rows.push_back(first + k);
  *G = P(rows, Eigen::all) * H_A.transpose();
  *P_rr = P(rows, rows);
}

/// `positions`: the objective vehicles' position rows; `vehicles`: their whole blocks (first
/// index, size), needed only by the log-det objective and the gain test.
SplitUpdate split(const Eigen::MatrixXd& P, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
                  const std::vector<int>& b_columns, const std::vector<int>& positions,
                  const std::vector<std::pair<int, int>>& vehicles = {}) {
  const Eigen::MatrixXd H_B = H(Eigen::all, b_columns);
  Eigen::MatrixXd H_A = H;
  H_A(Eigen::all, b_columns).setZero();
  SplitUpdate s;
  s.S_A = H_A * P * H_A.transpose();
  // n = b_columns.size() / 3 landmarks.
  s.S_B = (static_cast<double>(b_columns.size()) / 3.0) *
          (H_B * P(b_columns, b_columns) * H_B.transpose());
  s.R = R;
  std::vector<std::pair<int, int>> position_rows;
  for (int p : positions) position_rows.emplace_back(p, 3);
  gatherRows(P, H_A, position_rows, &s.G, &s.P_pp);
  gatherRows(P, H_A, vehicles, &s.G_V, &s.P_VV);
  return s;
}

}  // namespace

double ReactivationIntersection::positionTraceAfter(
    const Eigen::MatrixXd& P, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
    const std::vector<int>& b_columns, const std::vector<int>& p_indices, double omega) {
  return split(P, H, R, b_columns, p_indices).positionTrace(omega);
}

double ReactivationIntersection::vehicleLogDetAfter(
    const Eigen::MatrixXd& P, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
    const std::vector<int>& b_columns, const std::vector<std::pair<int, int>>& vehicles,
    double omega) {
  return split(P, H, R, b_columns, {}, vehicles).vehicleLogDet(omega);
}

Status ReactivationIntersection::reactivate(
    SlamState& state, LandmarkBook& book, LandmarkArchive& archive, const std::vector<int64_t>& ids,
    const StereoUpdater& updater, const StereoFrameObservations& frame, ReactivationReport* report,
    const std::vector<VariableKey>& objective) {
  ReactivationReport local;
  ReactivationReport& r = report != nullptr ? *report : local;
  r = ReactivationReport();
  if (state.find(updater.vehicle()) == nullptr)
    return Status::Error("re-activation: vehicle not in the state");
  std::vector<int> p_indices;
  std::vector<std::pair<int, int>> blocks;
  for (const VariableKey& key :
       objective.empty() ? std::vector<VariableKey>{updater.vehicle()} : objective) {
    const StateVariable* vehicle = state.find(key);
    if (vehicle == nullptr) return Status::Error("re-activation: vehicle not in the state");
    p_indices.push_back(vehicle->index + vehicle::kPosition);
    blocks.emplace_back(vehicle->index, vehicle->size);
    r.position_trace_prior +=
        state.covariance().block(p_indices.back(), p_indices.back(), 3, 3).trace();
  }
  r.position_trace_after = r.position_trace_prior;

  std::vector<int64_t> sorted = ids;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int64_t> added;
  for (int64_t id : sorted) {
    if (reactivateLandmark(state, book, archive, id)) added.push_back(id);
  }
  r.landmarks = static_cast<int>(added.size());
  if (added.empty()) return Status::Ok();

  std::vector<VariableKey> keys_b;
  std::vector<int> b_columns;
  for (int64_t id : added) {
    const VariableKey key = VariableKey::landmark(static_cast<uint64_t>(id));
    const StateVariable* v = state.find(key);
    keys_b.push_back(key);
    for (int k = 0; k < v->size; ++k) b_columns.push_back(v->index + k);
  }
  if (Status s = updater.linearise(state, book, frame, StereoUpdater::Selection::kOnlyListed, added,
                                   StereoUpdater::Jacobians::kFilter, 1.0, &batch_);
      !s.ok()) {
    return s;
  }
  // Unseen (behind the camera): no gain to weigh; intersected anyway, the archive's estimates
  // count for little, Q/(1 − max_omega).
  double omega = w_.max_omega;
  // The archive keeps marginals only: the landmarks' errors may be correlated with each other
  // too (all carry the vehicle's global error of their time), so each gets (1 − ω)/n.
  const double n = static_cast<double>(added.size());
  bool gain = batch_.rows() > 0;
  if (batch_.rows() > 0) {
    const bool by_log_det = w_.objective == ReactivationOptions::Objective::kVehicleLogDet;
    const SplitUpdate s =
        split(state.covariance(), batch_.H(), batch_.R(), b_columns, p_indices,
              by_log_det || w_.remap_without_gain ? blocks : std::vector<std::pair<int, int>>{});
    auto cost = [&](double w) { return by_log_det ? s.vehicleLogDet(w) : s.positionTrace(w); };
    omega = minimizeGoldenSection(cost, w_.min_omega, w_.max_omega, 1e-4).x;
    double best = cost(omega);
    for (double bound : {w_.min_omega, w_.max_omega}) {
      if (const double c = cost(bound); c < best) {
        omega = bound;
        best = c;
      }
    }
    // The objective's value at ω is `best`; the other quantity is evaluated once.
    r.position_trace_after = by_log_det ? s.positionTrace(omega) : best;
    if (w_.remap_without_gain)
      gain = (by_log_det ? best : s.vehicleLogDet(omega)) < SplitUpdate::logDet(s.P_VV);
  }
  if (w_.remap_without_gain && !gain) {
    // Out of the state again, exactly (they are uncorrelated with it until scaled) and out of
    // the book: the initialiser maps them anew from this frame.
    for (int64_t id : added) {
      CovarianceHelper::marginalize(state, VariableKey::landmark(static_cast<uint64_t>(id)));
      book.remove(id);
    }
    r.remapped = r.landmarks;
    r.landmarks = 0;
    r.position_trace_after = r.position_trace_prior;
    return Status::Ok();
  }
  r.omega = omega;
  // blockdiag(P_A/ω, Q/(1 − ω)): everything by 1/ω, then the re-activated block by ω/(1 − ω).
  if (Status s = CovarianceHelper::scaleCovariance(state, 1.0 / omega); !s.ok()) return s;
  return CovarianceHelper::scaleCovariance(state, keys_b, n * omega / (1.0 - omega));
}

}  // namespace cvslam
