#include "cvslam/insgps/sdc_factorisation.h"

#include <cmath>

#include "cvslam/ins/ins_propagator.h"
#include "cvslam/insgps/gps_measurement.h"

namespace cvslam::insgps {

namespace {

template <typename Out>
Eigen::Matrix<double, Out::RowsAtCompileTime, kStateSize> staircase(
    const std::function<Out(const StateVector&)>& g, const StateVector& x,
    const std::array<int, kStateSize>& order, const SdcOptions& o) {
  Eigen::Matrix<double, Out::RowsAtCompileTime, kStateSize> A;
  StateVector partial = StateVector::Zero();
  Out g_prev = g(partial);
  for (int j : order) {
    const double xj = x(j);
    if (std::abs(xj) < o.small_coordinate) {
      StateVector plus = partial, minus = partial;
      plus(j) += o.derivative_step;
      minus(j) -= o.derivative_step;
      A.col(j) = (g(plus) - g(minus)) / (2.0 * o.derivative_step);
      partial(j) = xj;
      // Keep the telescoping exact: the next quotient starts from g at the true partial path.
      g_prev = g(partial);
      continue;
    }
    partial(j) = xj;
    const Out g_next = g(partial);
    A.col(j) = (g_next - g_prev) / xj;
    g_prev = g_next;
  }
  return A;
}

}  // namespace

StateMatrix staircaseSdc(const StateFunction& g, const StateVector& x,
                         const std::array<int, kStateSize>& order, const SdcOptions& o) {
  return staircase<StateVector>(g, x, order, o);
}

MeasJacobian staircaseSdc(const MeasFunction& g, const StateVector& x,
                          const std::array<int, kStateSize>& order, const SdcOptions& o) {
  return staircase<MeasVector>(g, x, order, o);
}

std::array<int, kStateSize> forwardOrder() {
  return {0, 1, 2, 3, 4, 5, 6, 7, 8};
}
std::array<int, kStateSize> reverseOrder() {
  return {8, 7, 6, 5, 4, 3, 2, 1, 0};
}

StateVector insDynamics(const StateVector& x, const ImuSample& s, double gravity) {
  const Eigen::Matrix<double, kNoiseSize, 1> w = Eigen::Matrix<double, kNoiseSize, 1>::Zero();
  return InsPropagator::dynamics<double, kStateSize>(x, s.gyro_B, s.accel_B, w, gravity);
}

InsSdc insSdc(const StateVector& x, const ImuSample& s, double gravity, double alpha,
              const SdcOptions& o) {
  InsSdc out;
  out.b = insDynamics(StateVector::Zero(), s, gravity);
  const StateFunction g = [&](const StateVector& z) {
    return StateVector(insDynamics(z, s, gravity) - out.b);
  };
  const MeasFunction h = [](const StateVector& z) { return gpsPredicted(z); };
  out.A = alpha * staircaseSdc(g, x, forwardOrder(), o) +
          (1.0 - alpha) * staircaseSdc(g, x, reverseOrder(), o);
  out.H = alpha * staircaseSdc(h, x, forwardOrder(), o) +
          (1.0 - alpha) * staircaseSdc(h, x, reverseOrder(), o);
  return out;
}

}  // namespace cvslam::insgps
