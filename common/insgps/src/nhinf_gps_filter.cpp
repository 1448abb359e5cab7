#include "cvslam/insgps/nhinf_gps_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

Status NhinfOptions::load(const ConfigNode& node) {
  node.get("gamma", gamma);
  node.get("delta1", delta1);
  node.get("delta2", delta2);
  node.get("delta3", delta3);
  node.get("theta_backoff", theta_backoff);
  node.check(gamma > 0.0, "gamma", "must be > 0");
  node.check(delta1 >= 0.0 && delta2 >= 0.0 && delta3 >= 0.0, "delta1",
             "delta1, delta2, delta3 must be >= 0");
  node.check(theta_backoff > 0.0 && theta_backoff < 1.0, "theta_backoff", "must be in (0, 1)");
  node.check(cv2() > 0.0, "gamma", "too small for the deltas: need gamma^2 > delta1^2 + delta3^2");
  return node.status();
}

StateMatrix hinfPosteriorBlockForm(const StateMatrix& P, const MeasJacobian& H, const MeasMatrix& R,
                                   double theta) {
  // [C; H] with C = I, Λ = [C P Cᵀ − γ² I, C P Hᵀ; H P Cᵀ, H P Hᵀ + R], P⁺ = P − P [Cᵀ Hᵀ] Λ⁻¹
  // [C; H] P: eqs. 3.49–3.50 with C replaced by −C, which changes nothing (the sign cancels).
  constexpr int kN = kStateSize + kMeasSize;
  Eigen::Matrix<double, kN, kStateSize> CH;
  CH << StateMatrix::Identity(), H;
  Eigen::Matrix<double, kN, kN> Lambda = CH * P * CH.transpose();
  Lambda.topLeftCorner<kStateSize, kStateSize>() -= StateMatrix::Identity() / theta;
  Lambda.bottomRightCorner<kMeasSize, kMeasSize>() += R;
  return P - P * CH.transpose() * Lambda.inverse() * CH * P;
}

NhinfGpsFilter::NhinfGpsFilter(const InsPropagatorOptions& ins, const NhinfOptions& options)
    : GpsAidedEkf(ins, EkfOptions{}), ho_(options) {}

Status NhinfGpsFilter::propagate(const ImuSample& s0, const ImuSample& s1) {
  return predict(s0, s1, 1.0 / ho_.cw2());
}

Status NhinfGpsFilter::update(const GpsFix& fix) {
  const MeasJacobian H = gpsJacobian(x_);
  const MeasMatrix R_inv = (insgps::gpsCovariance(fix) / ho_.cv2()).inverse();
  const StateMatrix info = P_.inverse() + H.transpose() * R_inv * H;
  double theta = 1.0 / (ho_.gamma * ho_.gamma);
  const double lambda_min = Eigen::SelfAdjointEigenSolver<StateMatrix>(info).eigenvalues()(0);
  if (!(lambda_min - theta > 0.0)) {
    theta = ho_.theta_backoff * lambda_min;
    ++backoffs_;
  }
  StateMatrix P_post = (info - theta * StateMatrix::Identity()).inverse();
  P_post = 0.5 * (P_post + P_post.transpose()).eval();
  const Eigen::Matrix<double, kStateSize, kMeasSize> K = P_post * H.transpose() * R_inv;
  x_ = wrapYaw(x_ + K * (insgps::gpsMeasurement(fix) - gpsPredicted(x_)));
  P_ = P_post;
  return Status::Ok();
}

}  // namespace cvslam::insgps
