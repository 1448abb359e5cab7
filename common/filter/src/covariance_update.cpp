// CovarianceHelper::update: Mahalanobis gating, EKF (Joseph) and NH∞ measurement updates.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <array>
#include <string>

#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/filter/invariant_chart_transport.h"

namespace cvslam {
namespace {

/// Small per-observation blocks (stereo: 4 rows) live on the stack.
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;

/// Squared Mahalanobis distance rᵀ S⁻¹ r; negative when S is not positive definite.
double mahalanobis2(const Eigen::Ref<const Eigen::MatrixXd>& S,
                    const Eigen::Ref<const Eigen::VectorXd>& r) {
  if (S.rows() <= 8) {
    const Eigen::LLT<SmallMatrix> llt{SmallMatrix(S)};
    if (llt.info() != Eigen::Success) return -1.0;
    return llt.matrixL().solve(SmallVector(r)).squaredNorm();
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return -1.0;
  return llt.matrixL().solve(r).squaredNorm();
}

/// Rows of one accepted observation in the batch.
struct AcceptedGroup {
  int source_row = 0;  ///< first row in the batch
  int rows = 0;
};

/// Applies the gate; returns the accepted observations.
std::vector<AcceptedGroup> gate(const MeasurementBatch& batch, const Eigen::MatrixXd& S,
                                double probability, UpdateReport* report) {
  std::vector<AcceptedGroup> accepted;
  accepted.reserve(static_cast<std::size_t>(batch.groups()));
  std::array<double, 17> threshold{};  // per dof, computed on first use
  for (int g = 0; g < batch.groups(); ++g) {
    const int r0 = batch.groupRow(g), nr = batch.groupRows(g);
    bool accept = true;
    if (probability > 0.0) {
      const double d2 = mahalanobis2(S.block(r0, r0, nr, nr), batch.residual().segment(r0, nr));
      double limit = 0.0;
      if (nr < static_cast<int>(threshold.size())) {
        double& t = threshold[static_cast<std::size_t>(nr)];
        if (t == 0.0) t = chiSquareQuantile(probability, nr);
        limit = t;
      } else {
        limit = chiSquareQuantile(probability, nr);
      }
      accept = d2 >= 0.0 && d2 <= limit;
    }
    if (accept) {
      accepted.push_back({r0, nr});
      ++report->observations_accepted;
    } else {
      ++report->observations_rejected;
    }
  }
  return accepted;
}

/// The policy's θ when θ λ_max(X) ≤ theta_margin (eq. 3.40 with a margin, checked by a
/// Cholesky of margin·I − θ X), else half the admissible θ (report->theta_reduced).
double admissibleTheta(const UpdatePolicy& policy, const Eigen::MatrixXd& X, UpdateReport* report) {
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(X.rows(), X.rows());
  const Eigen::LLT<Eigen::MatrixXd> admissible(policy.theta_margin * I - policy.theta * X);
  if (admissible.info() == Eigen::Success) return policy.theta;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(X, Eigen::EigenvaluesOnly);
  report->theta_reduced = true;
  return 0.5 * policy.theta_margin / eig.eigenvalues().maxCoeff();
}

/// Step 5 of the update, NH∞ (eq. 3.39 with S = I or S = Π, see UpdatePolicy::theta_weighting):
/// turns the EKF posterior P into the NH∞ one for the accepted `rows` of the batch. Returns the
/// θ applied (reduced when eq. 3.40 fails with the policy's), or a negative value on failure.
double applyTheta(const UpdatePolicy& policy, const MeasurementBatch& batch,
                  const std::vector<int>& rows, Eigen::MatrixXd& P, UpdateReport* report) {
  const Eigen::Index n = P.rows();
  double theta = 0.0;
  if (policy.theta_weighting == ThetaWeighting::kIdentity) {
    // P⁺ = (P⁻⁻¹ + Hᵀ R⁻¹ H − θ I)⁻¹ = (P_EKF⁻¹ − θ I)⁻¹ = (I − θ P_EKF)⁻¹ P_EKF.
    // Eq. 3.40 (P⁺ > 0) ⇔ θ λ_max(P_EKF) < 1; we require ≤ theta_margin.
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
    theta = admissibleTheta(policy, P, report);
    const Eigen::LLT<Eigen::MatrixXd> M_llt(I - theta * P);
    if (M_llt.info() != Eigen::Success) {
      return -1.0;
    }
    P = M_llt.solve(P);
  } else {
    // P⁺ = (P_EKF⁻¹ − θ Π)⁻¹ with Π = Q Qᵀ the projector onto range(Hᵀ) (the state
    // directions this update observes). By Woodbury
    //   P⁺ = P_EKF + P_EKF Q (θ⁻¹ I − Qᵀ P_EKF Q)⁻¹ Qᵀ P_EKF,
    // positive definite iff θ λ_max(Qᵀ P_EKF Q) < 1 (eq. 3.40 on the observed subspace).
    // Directions H cannot see — SLAM's gauge (a common shift or yaw of vehicle and map)
    // and unobserved landmarks — keep the EKF's information, so θ cannot inflate them
    // without bound as it does with S = I.
    Eigen::MatrixXd Ht(n, static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) {
      Ht.col(static_cast<Eigen::Index>(i)) = batch.H().row(rows[i]).transpose();
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ht);
    const Eigen::Index rank = qr.rank();
    const Eigen::MatrixXd Q = (qr.householderQ() * Eigen::MatrixXd::Identity(n, rank)).eval();
    const Eigen::MatrixXd PQ = P * Q;
    const Eigen::MatrixXd M = Q.transpose() * PQ;
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(rank, rank);
    theta = admissibleTheta(policy, M, report);
    const Eigen::LLT<Eigen::MatrixXd> C_llt(I / theta - M);
    if (C_llt.info() != Eigen::Success) {
      return -1.0;
    }
    P.noalias() += PQ * C_llt.solve(PQ.transpose());
  }
  P = 0.5 * (P + P.transpose()).eval();
  return theta;
}

}  // namespace

Status CovarianceHelper::update(SlamState& state, const MeasurementBatch& batch,
                                const UpdatePolicy& policy, UpdateReport* report_out) {
  UpdateReport report;
  const int n = state.size();
  if (batch.stateSize() != n) {
    return Status::Error("update: batch built for a state of " + std::to_string(batch.stateSize()) +
                         ", state has " + std::to_string(n));
  }
  if (!(policy.measurement_noise_scale > 0.0) || !(policy.theta >= 0.0) ||
      !(policy.theta_margin > 0.0 && policy.theta_margin <= 1.0)) {
    return Status::Error("update: invalid policy (c_v² must be > 0, θ ≥ 0, margin in (0, 1])");
  }
  const Eigen::MatrixXd& P = state.P_;

  // 1. Innovation covariance S = H P Hᵀ + c_v² R, sparse in H.
  Eigen::MatrixXd PHt, S;
  batch.multiplyByHt(P, &PHt);
  batch.multiplyH(PHt, &S);
  S.noalias() += policy.measurement_noise_scale * batch.R();

  // 2. Mahalanobis gate per observation; keep the accepted rows only.
  const std::vector<AcceptedGroup> groups = gate(batch, S, policy.gate_probability, &report);
  if (groups.empty()) {
    if (report_out) *report_out = report;
    return Status::Ok();
  }
  std::vector<int> rows;
  rows.reserve(static_cast<std::size_t>(batch.rows()));
  for (const AcceptedGroup& g : groups)
    for (int i = 0; i < g.rows; ++i) rows.push_back(g.source_row + i);
  const bool all = static_cast<int>(rows.size()) == batch.rows();
  const Eigen::MatrixXd PHt_a = all ? PHt : Eigen::MatrixXd(PHt(Eigen::all, rows));
  const Eigen::MatrixXd S_a = all ? S : Eigen::MatrixXd(S(rows, rows));
  const Eigen::VectorXd r_a =
      all ? Eigen::VectorXd(batch.residual()) : Eigen::VectorXd(batch.residual()(rows));

  // 3. Gain from the prior, K = P Hᵀ S⁻¹ (eq. 3.22; for NH∞ eq. 3.48 with the H∞ prior).
  const Eigen::LLT<Eigen::MatrixXd> S_llt(S_a);
  if (S_llt.info() != Eigen::Success) {
    return Status::Error("update: innovation covariance is not positive definite");
  }
  // Held landmarks are Schmidt variables: zero gain. The Joseph form below is exact for any
  // gain, so their covariance stays and their cross-covariances get (I − KH) P.
  Eigen::MatrixXd K = S_llt.solve(PHt_a.transpose()).transpose();
  std::vector<int> corrected;  // rows of the variables with a gain: all but held landmarks
  corrected.reserve(static_cast<std::size_t>(n));
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind == VariableKey::Kind::kHeldLandmark) {
      K.middleRows(v.index, v.size).setZero();
    } else {
      for (int k = 0; k < v.size; ++k) corrected.push_back(v.index + k);
    }
  }
  const Eigen::VectorXd dx = K * r_a;
  report.rows = static_cast<int>(rows.size());
  report.nis = S_llt.matrixL().solve(r_a).squaredNorm();

  // 4. Joseph form (eq. 3.23) as a symmetric rank-2m update: with W = P Hᵀ − ½ K S,
  //    (I − KH) P (I − KH)ᵀ + c_v² K R Kᵀ = P − K (HP) − (HP)ᵀ Kᵀ + K S Kᵀ = P − (W Kᵀ + K Wᵀ),
  //    exact for any K (the Schmidt gain above) and, like the factored Joseph form, insensitive
  //    to first order to errors in K (for the optimal K, W = ½ K S and the first-order terms
  //    cancel). Only the lower triangle of [W K][K W]ᵀ is formed, n² m multiply-adds against
  //    the factored form's 2 n² m (`bench_filter_step` BM_UpdateLargeMap), then mirrored.
  //    P − K S Kᵀ alone is cheaper still but is not insensitive to errors in K, and it lost
  //    positive definiteness on a full-map run (euroc_mh03_hall seed 226, 67 s).
  //    With held landmarks (rows of K zero) the held–held block of W Kᵀ + K Wᵀ is zero: only
  //    the columns of the corrected variables C change, D = W K_Cᵀ + K W_Cᵀ (2 n n_C m), and
  //    their rows by symmetry. Cheaper than the triangle when n_C < n / 2: with 100–300 held
  //    landmarks most of a k-nearest state (`bench_filter_step` BM_UpdateHeld).
  const Eigen::Index m = K.cols();
  Eigen::MatrixXd W = PHt_a;
  W.noalias() -= 0.5 * (K * S_a);
  // The EKF updates P in place (nothing can fail after the gain); NH∞ works on a copy, which
  // step 5 may refuse.
  Eigen::MatrixXd P_copy;
  const bool nhinf = policy.theta > 0.0;
  if (nhinf) P_copy = P;
  Eigen::MatrixXd& P_post = nhinf ? P_copy : state.P_;
  if (2 * corrected.size() < static_cast<std::size_t>(n)) {
    const Eigen::MatrixXd W_c = W(corrected, Eigen::all), K_c = K(corrected, Eigen::all);
    Eigen::MatrixXd D = W * K_c.transpose();
    D.noalias() += K * W_c.transpose();
    for (std::size_t k = 0; k < corrected.size(); ++k) {
      P_post.col(corrected[k]) -= D.col(static_cast<Eigen::Index>(k));
    }
    for (int c : corrected) P_post.row(c) = P_post.col(c).transpose();
  } else {
    Eigen::MatrixXd left(n, 2 * m), right(n, 2 * m);
    left.leftCols(m) = W;
    left.rightCols(m) = K;
    right.leftCols(m) = K;
    right.rightCols(m) = W;
    P_post.triangularView<Eigen::Lower>() -= left * right.transpose();
    for (Eigen::Index j = 0; j + 1 < n; ++j) {
      P_post.row(j).tail(n - j - 1) = P_post.col(j).tail(n - j - 1).transpose();
    }
  }

  // 5. NH∞ (eq. 3.39).
  double theta = 0.0;
  if (nhinf) {
    theta = applyTheta(policy, batch, rows, P_post, &report);
    if (theta < 0.0) {
      return Status::Error("update: NH∞ posterior not positive definite after reducing θ");
    }
  }
  report.theta_used = theta;

  if (nhinf) state.P_ = std::move(P_copy);
  // In the invariant chart a landmark without an anchor of its own takes the rotation error of
  // the vehicle these observations are of (the first whose attitude columns H uses).
  const VariableKey* observer =
      state.chart_ == ErrorChart::kRightInvariant ? observingVehicle(state, batch) : nullptr;
  correctMean(state, dx, observer);
  if (report_out) *report_out = report;
  return Status::Ok();
}

}  // namespace cvslam
