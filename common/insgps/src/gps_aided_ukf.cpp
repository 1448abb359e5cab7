#include "cvslam/insgps/gps_aided_ukf.h"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>

#include "cvslam/insgps/gps_measurement.h"
#include "cvslam/insgps/kalman_correction.h"
#include "cvslam/io/config_node.h"

namespace cvslam::insgps {

namespace {

constexpr int kAugSize = kStateSize + kNoiseSize;  // 15
using AugVector = Eigen::Matrix<double, kAugSize, 1>;
using AugMatrix = Eigen::Matrix<double, kAugSize, kAugSize>;

/// Lower Cholesky factor of a covariance, with a diagonal jitter retry for the semidefinite
/// case (Q_w has no position entries).
template <int N>
Eigen::Matrix<double, N, N> squareRoot(const Eigen::Matrix<double, N, N>& P) {
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt(P);
  if (llt.info() == Eigen::Success) return llt.matrixL();
  constexpr double kRelativeJitter = 1e-12;  // numerical guard only, far below any variance
  const double jitter = kRelativeJitter * std::max(1.0, P.diagonal().maxCoeff());
  Eigen::LLT<Eigen::Matrix<double, N, N>> llt2(P +
                                               jitter * Eigen::Matrix<double, N, N>::Identity());
  return llt2.matrixL();
}

}  // namespace

Status UkfOptions::load(const ConfigNode& node) {
  node.get("alpha", alpha);
  node.get("beta", beta);
  node.get("kappa", kappa);
  node.check(alpha > 0.0 && alpha <= 1.0, "alpha", "must be in (0, 1]");
  node.check(beta >= 0.0, "beta", "must be >= 0");
  node.check(kStateSize + kappa > 0.0, "kappa", "must be > -9 (n + kappa > 0)");
  return node.status();
}

UnscentedWeights::UnscentedWeights(int n, const UkfOptions& o) {
  const double nd = static_cast<double>(n);
  const double lambda = o.alpha * o.alpha * (nd + o.kappa) - nd;
  scale = std::sqrt(nd + lambda);
  wm0 = lambda / (nd + lambda);
  wc0 = wm0 + 1.0 - o.alpha * o.alpha + o.beta;
  wi = 0.5 / (nd + lambda);
}

GpsAidedUkf::GpsAidedUkf(const InsPropagatorOptions& ins, const UkfOptions& options)
    : propagator_(insgpsPropagatorOptions(ins)), o_(options) {}

void GpsAidedUkf::initialize(const StateVector& x0, const StateMatrix& P0, int64_t /*t_us*/) {
  x_ = x0;
  P_ = P0;
}

Status GpsAidedUkf::propagate(const ImuSample& s0, const ImuSample& s1) {
  const double dt = 1e-6 * static_cast<double>(s1.t_us - s0.t_us);
  if (!(dt > 0.0) || dt > propagator_.options().max_dt)
    return Status::Error("ukf: IMU interval out of range (" + std::to_string(dt) + " s)");
  const Eigen::VectorXd q = propagator_.noiseVariances(dt);
  AugMatrix Pa = AugMatrix::Zero();
  Pa.topLeftCorner<kStateSize, kStateSize>() = P_;
  Pa.bottomRightCorner<kNoiseSize, kNoiseSize>() = q.asDiagonal();
  const AugMatrix L = squareRoot<kAugSize>(Pa);
  const UnscentedWeights w(kAugSize, o_);

  std::array<StateVector, 2 * kAugSize + 1> chi;
  auto pushThrough = [&](const AugVector& xa) {
    const Eigen::VectorXd x = xa.head<kStateSize>();
    const Eigen::VectorXd noise = xa.tail<kNoiseSize>();
    return wrapYaw(StateVector(propagator_.stepMean(x, s0, s1, noise)));
  };
  AugVector xa = AugVector::Zero();
  xa.head<kStateSize>() = x_;
  chi[0] = pushThrough(xa);
  for (int i = 0; i < kAugSize; ++i) {
    chi[1 + i] = pushThrough(xa + w.scale * L.col(i));
    chi[1 + kAugSize + i] = pushThrough(xa - w.scale * L.col(i));
  }
  StateVector mean_offset = StateVector::Zero();
  for (std::size_t i = 1; i < chi.size(); ++i)
    mean_offset += w.wi * stateDifference(chi[i], chi[0]);
  const StateVector mean = wrapYaw(chi[0] + mean_offset);
  StateMatrix P = StateMatrix::Zero();
  for (std::size_t i = 0; i < chi.size(); ++i) {
    const StateVector d = stateDifference(chi[i], mean);
    P += (i == 0 ? w.wc0 : w.wi) * d * d.transpose();
  }
  x_ = mean;
  P_ = 0.5 * (P + P.transpose());
  return Status::Ok();
}

Status GpsAidedUkf::update(const GpsFix& fix) {
  const StateMatrix L = squareRoot<kStateSize>(P_);
  const UnscentedWeights w(kStateSize, o_);
  std::array<StateVector, 2 * kStateSize + 1> chi;
  chi[0] = x_;
  for (int i = 0; i < kStateSize; ++i) {
    chi[1 + i] = wrapYaw(x_ + w.scale * L.col(i));
    chi[1 + kStateSize + i] = wrapYaw(x_ - w.scale * L.col(i));
  }
  std::array<MeasVector, 2 * kStateSize + 1> upsilon;
  MeasVector y_mean = MeasVector::Zero();
  for (std::size_t i = 0; i < chi.size(); ++i) {
    upsilon[i] = gpsPredicted(chi[i]);
    y_mean += (i == 0 ? w.wm0 : w.wi) * upsilon[i];
  }
  MeasMatrix S = insgps::gpsCovariance(fix);
  Eigen::Matrix<double, kStateSize, kMeasSize> Pxy =
      Eigen::Matrix<double, kStateSize, kMeasSize>::Zero();
  for (std::size_t i = 0; i < chi.size(); ++i) {
    const double wc = i == 0 ? w.wc0 : w.wi;
    const MeasVector dy = upsilon[i] - y_mean;
    S += wc * dy * dy.transpose();
    Pxy += wc * stateDifference(chi[i], x_) * dy.transpose();
  }
  const Eigen::LDLT<MeasMatrix> S_ldlt(S);
  const Eigen::Matrix<double, kStateSize, kMeasSize> K = S_ldlt.solve(Pxy.transpose()).transpose();
  x_ = wrapYaw(x_ + K * (insgps::gpsMeasurement(fix) - y_mean));
  P_ -= K * S * K.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return Status::Ok();
}

}  // namespace cvslam::insgps
