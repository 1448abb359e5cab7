#pragma once
// State-dependent coefficient (SDC) factorisations (thesis §3.5.2, eqs. 3.24–3.25):
// matrices A(x) with A(x) x = g(x) for a function g with g(0) = 0.
//
// The INS dynamics are affine in the IMU input u, ẋ = f(x, u), and f(0, u) ≠ 0 (gravity,
// specific force, body rates), so the SDC form used here is
//   ẋ = A(x, u) x + b(u),   b(u) = f(0, u),   A(x, u) x = f(x, u) − f(0, u),
// with b a known input (the "B u" of eq. 3.1). The thesis builds its A by hand from eqs.
// 2.9–2.10; we build it generically by the "staircase" of difference quotients along the
// coordinate path 0 → x taken in a chosen order o:
//   x⁽ʲ⁾ = x with only its first j coordinates (in order o) kept, the others 0;
//   column o_j of A = (g(x⁽ʲ⁾) − g(x⁽ʲ⁻¹⁾)) / x_{o_j}
// so that Σ_j A e_{o_j} x_{o_j} = g(x) − g(0) = g(x) exactly (a telescoping sum). When
// |x_{o_j}| is tiny the quotient is replaced by its limit, the partial derivative at x⁽ʲ⁻¹⁾
// (central difference). Different orders give different valid SDC forms: the thesis's F₁ and
// F₂ (§3.7.1), mixed as F(x, α) = α F₁ + (1 − α) F₂, itself an SDC form (eq. above 3.64).

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

using StateFunction = std::function<StateVector(const StateVector&)>;
using MeasFunction = std::function<MeasVector(const StateVector&)>;

/// Staircase SDC matrix of g (g(0) = 0 assumed; not checked) at x along coordinate order.
StateMatrix staircaseSdc(const StateFunction& g, const StateVector& x,
                         const std::array<int, kStateSize>& order, const SdcOptions& o = {});
MeasJacobian staircaseSdc(const MeasFunction& g, const StateVector& x,
                          const std::array<int, kStateSize>& order, const SdcOptions& o = {});

/// The two orders of F₁ (x₀ … x₈: position, velocity, attitude) and F₂ (reversed).
std::array<int, kStateSize> forwardOrder();
std::array<int, kStateSize> reverseOrder();

/// The INS SDC pair at x for the IMU input s (thesis §3.5.2):
///   A = α A_fwd + (1 − α) A_rev of f(x, s) − f(0, s), b = f(0, s),
///   H = α H_fwd + (1 − α) H_rev of h(x) (h(0) = 0 already).
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
