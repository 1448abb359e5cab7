#include "cvslam/slam/reactivation_intersection.h"

#include <algorithm>

#include <Eigen/Cholesky>

#include "cvslam/core/golden_section.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/slam/landmark_lifecycle.h"

namespace cvslam {

namespace {

/// The pieces of the split-prior update that do not depend on ω. With H = [H_A H_B] and the
/// prior blockdiag(P_A/ω, n·P_B/(1 − ω)) (n landmarks in B), the innovation covariance is
/// S_A/ω + S_B/(1 − ω) + R with S_B = n·H_B P_B H_Bᵀ, and the position rows of P H̃ᵀ are G/ω,
/// so the posterior position covariance is P_pp/ω − G S⁻¹ Gᵀ/ω² (P_pp and G over the position
/// rows of every vehicle of the objective).
struct SplitUpdate {
  Eigen::MatrixXd S_A, S_B, R, G;
  double trace_pp = 0.0;

  double positionTrace(double omega) const {
    const Eigen::MatrixXd S = S_A / omega + S_B / (1.0 - omega) + R;
    return trace_pp / omega - (G * S.ldlt().solve(G.transpose())).trace() / (omega * omega);
  }
};

SplitUpdate split(const Eigen::MatrixXd& P, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
                  const std::vector<int>& b_columns, const std::vector<int>& p_indices) {
  const auto m = H.rows();
  const auto nb = static_cast<Eigen::Index>(b_columns.size());
  Eigen::MatrixXd H_A = H, H_B(m, nb), P_BB(nb, nb);
  for (Eigen::Index i = 0; i < nb; ++i) {
    H_B.col(i) = H.col(b_columns[static_cast<std::size_t>(i)]);
    H_A.col(b_columns[static_cast<std::size_t>(i)]).setZero();
    for (Eigen::Index j = 0; j < nb; ++j)
      P_BB(i, j) =
          P(b_columns[static_cast<std::size_t>(i)], b_columns[static_cast<std::size_t>(j)]);
  }
  SplitUpdate s;
  s.S_A = H_A * P * H_A.transpose();
  s.S_B = (static_cast<double>(nb) / 3.0) * (H_B * P_BB * H_B.transpose());  // n = nb / 3
  s.R = R;
  s.G.resize(3 * static_cast<Eigen::Index>(p_indices.size()), m);
  for (std::size_t k = 0; k < p_indices.size(); ++k) {
    const auto row = 3 * static_cast<Eigen::Index>(k);
    s.G.middleRows(row, 3) = P.middleRows(p_indices[k], 3) * H_A.transpose();
    s.trace_pp += P.block(p_indices[k], p_indices[k], 3, 3).trace();
  }
  return s;
}

}  // namespace

double ReactivationIntersection::positionTraceAfter(
    const Eigen::MatrixXd& P, const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
    const std::vector<int>& b_columns, const std::vector<int>& p_indices, double omega) {
  return split(P, H, R, b_columns, p_indices).positionTrace(omega);
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
  for (const VariableKey& key :
       objective.empty() ? std::vector<VariableKey>{updater.vehicle()} : objective) {
    const StateVariable* vehicle = state.find(key);
    if (vehicle == nullptr) return Status::Error("re-activation: vehicle not in the state");
    p_indices.push_back(vehicle->index + vehicle::kPosition);
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
  // Unseen (behind the camera) or nothing to gain: the archive's estimates are kept but count
  // for little, Q/(1 − max_omega).
  double omega = w_.max_omega;
  // The archive keeps marginals only: the landmarks' errors may be correlated with each other
  // too (all carry the vehicle's global error of their time), so each gets (1 − ω)/n.
  const double n = static_cast<double>(added.size());
  if (batch_.rows() > 0) {
    const SplitUpdate s = split(state.covariance(), batch_.H(), batch_.R(), b_columns, p_indices);
    auto cost = [&](double w) { return s.positionTrace(w); };
    omega = minimizeGoldenSection(cost, w_.min_omega, w_.max_omega, 1e-4).x;
    for (double bound : {w_.min_omega, w_.max_omega}) {
      if (cost(bound) < cost(omega)) omega = bound;
    }
    r.position_trace_after = cost(omega);
  }
  r.omega = omega;
  // blockdiag(P_A/ω, Q/(1 − ω)): everything by 1/ω, then the re-activated block by ω/(1 − ω).
  if (Status s = CovarianceHelper::scaleCovariance(state, 1.0 / omega); !s.ok()) return s;
  return CovarianceHelper::scaleCovariance(state, keys_b, n * omega / (1.0 - omega));
}

}  // namespace cvslam
