#pragma once
// State-dependent coefficient (SDC) factorisations (thesis §3.5.2, eqs. 3.24–3.25):
// matrices A(x) with A(x) x = g(x) for a function g with g(0) = 0.
//
// The INS dynamics are affine in the IMU input u, ẋ = f(x, u), and f(0, u) ≠ 0 (gravity,
// specific force, body rates), so the SDC form used here is
//   ẋ = A(x, u) x + b(u),   b(u) = f(0, u),   A(x, u) x = f(x, u) − f(0, u),
// with b a known input (the "B u" of eq. 3.1). As the thesis notes (§3.5.2), eqs. 2.5–2.7
// fall "naturally" into this form:
//   ṗ   = R_BtoN(e) v_B                       → A_pv = R_BtoN(e)
//   v̇_B = −[ω]× v_B + (R_NtoB(e) − I) g + (f + g)   → A_vv = −[ω]×, A_ve = C_g(e)
//   ė   = (E(e) − I) ω + ω                     → A_ee = C_E(e)
//   h(x) = [p ; R_BtoN(e) v_B]                 → H = [I 0 0 ; 0 R_BtoN(e) 0]
// where C_g, C_E are SDC matrices of the attitude-only functions c(e) = (R_NtoB(e) − I) g and
// (E(e) − I) ω, both zero at e = 0. These are built by the "staircase" of difference
// quotients along the coordinate path 0 → e taken in an order o:
//   e⁽ʲ⁾ = e with only its first j coordinates (in order o) kept, the others 0;
//   column o_j = (c(e⁽ʲ⁾) − c(e⁽ʲ⁻¹⁾)) / e_{o_j}
// so that Σ_j C e_{o_j} e_{o_j} = c(e) − c(0) = c(e) exactly (a telescoping sum). When
// |e_{o_j}| is tiny the quotient is replaced by its limit, the partial derivative at e⁽ʲ⁻¹⁾
// (central difference). The orders φθψ and ψθφ give the thesis's two SDC forms F₁ and F₂
// (§3.7.1), mixed as F(x, α) = α F₁ + (1 − α) F₂, itself an SDC form.
// Consequence of the natural form: yaw enters neither C_g (gravity is vertical) nor C_E nor
// H, so the frozen pair (A, H) cannot see it; the SDRE filter does not correct yaw
// (docs/ins_gps.md).

#include <Eigen/Core>
#include <array>
#include <functional>

#include "cvslam/ins/imu_sample.h"
#include "cvslam/insgps/gps_aided_filter.h"

namespace cvslam::insgps {

/// Below this |x_j| the staircase column is the partial derivative (central difference of
/// step `derivative_step`), which the quotient tends to; avoids dividing by ~0.
struct SdcOptions {
  double small_coordinate = 1e-6;
  double derivative_step = 1e-6;
};

using AttitudeFunction = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// Staircase SDC matrix C(e) of c (c(0) = 0 assumed) along the coordinate order of e.
Eigen::Matrix3d staircaseSdc(const AttitudeFunction& c, const Eigen::Vector3d& e,
                             const std::array<int, 3>& order, const SdcOptions& o = {});

/// The orders of F₁ (φ θ ψ) and F₂ (ψ θ φ).
constexpr std::array<int, 3> kForwardOrder = {0, 1, 2};
constexpr std::array<int, 3> kReverseOrder = {2, 1, 0};

/// The INS SDC pair at x for the IMU input s (above; α mixes the attitude blocks).
struct InsSdc {
  StateMatrix A;
  StateVector b;
  MeasJacobian H;
};
InsSdc insSdc(const StateVector& x, const ImuSample& s, double gravity, double alpha,
              const SdcOptions& o = {});

/// f(x, s) with zero noise: the continuous INS dynamics (InsPropagator::dynamics).
StateVector insDynamics(const StateVector& x, const ImuSample& s, double gravity);

}  // namespace cvslam::insgps
