#include "cvslam/coop/request_timeout.h"

#include <algorithm>
#include <cmath>

namespace cvslam::coop {

namespace {
// RFC 6298 §2: α = 1/8, β = 1/4, K = 4.
constexpr double kAlpha = 0.125;
constexpr double kBeta = 0.25;
constexpr double kVarianceWeight = 4.0;
constexpr double kBackOff = 2.0;  // RFC 6298 §5.5
}  // namespace

void RequestTimeout::onAnswer(double round_trip_s) {
  if (!std::isfinite(round_trip_s) || round_trip_s < 0.0) return;
  if (srtt_s_ < 0.0) {
    srtt_s_ = round_trip_s;
    rttvar_s_ = round_trip_s / 2.0;
  } else {
    rttvar_s_ = (1.0 - kBeta) * rttvar_s_ + kBeta * std::abs(srtt_s_ - round_trip_s);
    srtt_s_ = (1.0 - kAlpha) * srtt_s_ + kAlpha * round_trip_s;
  }
  rto_s_ = std::clamp(srtt_s_ + kVarianceWeight * rttvar_s_, o_.min_s, o_.max_s);
}

void RequestTimeout::onTimeout() {
  rto_s_ = std::min(kBackOff * rto_s_, o_.max_s);
}

}  // namespace cvslam::coop
