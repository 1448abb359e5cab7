#pragma once
// Unscented Kalman filter for GPS-aided INS (thesis §3.5, the UKF the SDRE is compared with
// in Fig. 3.9 and Tables 3.2–3.3; Julier & Uhlmann's scaled unscented transform).
//
// Prediction: the state is augmented with the IMU white noise, x_a = [x ; w] (9 + 6), and
// each of the 2·15 + 1 sigma points is pushed through the same RK4 mechanisation as the other
// filters (InsPropagator::stepMean with its own w) — no Jacobian anywhere. Correction: 2·9 + 1
// sigma points of the prediction through h(x). Angle residuals are wrapped (stateDifference),
// and the mean of the sigma points is taken as χ₀ + Σ Wᵢ (χᵢ ⊟ χ₀) so that yaw near ±π
// averages correctly.

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

struct UkfOptions {
  double alpha = 1.0;  ///< spread of the sigma points (scaled UT, 0 < α ≤ 1)
  double beta = 2.0;   ///< prior knowledge of the distribution (2: Gaussian)
  double kappa = 0.0;  ///< secondary scaling (n + κ > 0)

  Status load(const ConfigNode& node);
};

/// Weights and spread of the scaled unscented transform in dimension n.
struct UnscentedWeights {
  double scale = 0.0;  ///< √(n + λ): sigma point i = mean ± scale · column i of √P
  double wm0 = 0.0, wc0 = 0.0, wi = 0.0;  ///< mean weight of χ₀, covariance weight, others
  UnscentedWeights(int n, const UkfOptions& o);
};

class GpsAidedUkf : public GpsAidedFilter {
 public:
  GpsAidedUkf(const InsPropagatorOptions& ins, const UkfOptions& options = {});
  std::string name() const override { return "ukf"; }
  void initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) override;
  Status propagate(const ImuSample& s0, const ImuSample& s1) override;
  Status update(const GpsFix& fix) override;
  StateVector state() const override { return x_; }
  StateMatrix covariance() const override { return P_; }

 private:
  InsPropagator propagator_;
  UkfOptions o_;
  StateVector x_ = StateVector::Zero();
  StateMatrix P_ = StateMatrix::Identity();
};

}  // namespace cvslam::insgps
