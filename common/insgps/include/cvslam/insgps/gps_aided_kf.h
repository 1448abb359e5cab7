#pragma once
// Linear Kalman filter on the INS error model (thesis §3.3, eqs. 3.1–3.12), open loop.
//
// The INS runs alone (the nominal x_ins, pure mechanisation from the initial estimate, never
// corrected); the KF estimates its error δx = x − x_ins with the linear error model
//   δx_k = F_k δx_{k−1} + Γ_k w_k,   z_k = y_k − h(x_ins) = H_k δx_k + v_k   (eqs. 3.1, 3.3)
// F_k, Γ_k, H_k are the Jacobians along the INS solution (known before any fix: the
// "linearised" KF of §3.4's first paragraph), so the filter is linear in δx. The estimate is
// x_ins + δx̂. As the INS drifts, the first-order error model gets worse; with sharp
// manoeuvres this is the thesis's observation that the KF is adequate "only for small
// angular rates" (§3.7.2.1, Fig. 3.6). Option `reset_interval_s` turns it into the closed
// loop form (δx̂ folded into the INS every so often), for comparison.

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::insgps {

struct KfOptions {
  bool joseph_form = true;  ///< eq. 3.12 instead of eq. 3.11
  /// Folds δx̂ into the INS nominal (and zeroes it) at the first fix after each such interval
  /// [s]; 0: never (the thesis's open-loop KF on the error model).
  double reset_interval_s = 0.0;

  Status load(const ConfigNode& node);
};

class GpsAidedKf : public GpsAidedFilter {
 public:
  GpsAidedKf(const InsPropagatorOptions& ins, const KfOptions& options = {});
  std::string name() const override { return "kf"; }
  void initialize(const StateVector& x0, const StateMatrix& P0, int64_t t_us) override;
  Status propagate(const ImuSample& s0, const ImuSample& s1) override;
  Status update(const GpsFix& fix) override;
  StateVector state() const override { return wrapYaw(x_ins_ + dx_); }
  StateMatrix covariance() const override { return P_; }
  /// The free-running INS solution (the nominal of the error model).
  const StateVector& insSolution() const { return x_ins_; }

 private:
  InsPropagator propagator_;
  KfOptions o_;
  StateVector x_ins_ = StateVector::Zero();
  StateVector dx_ = StateVector::Zero();
  StateMatrix P_ = StateMatrix::Identity();
  int64_t t_us_ = 0;
  int64_t last_reset_us_ = 0;
};

}  // namespace cvslam::insgps
