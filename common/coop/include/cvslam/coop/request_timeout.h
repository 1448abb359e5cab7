#pragma once
// How long a DC agent waits for the answer to a SharedRequest before it abandons the request
// and asks again (dc_cooperation.h, docs/cooperation.md "Loss"): TCP's retransmission timer
// (RFC 6298) in dataset time, one per peer. A lost request or answer used to block the
// exchange with that peer for a fixed request_timeout_s (2 s), longer than a typical overlap
// of two UAVs' views; the answer of a healthy link comes within a few frames, so the timer
// follows the measured round trip instead:
//   RTO = clamp(SRTT + 4·RTTVAR, min, max), SRTT/RTTVAR smoothed with gains 1/8 and 1/4;
//   before the first answer RTO = min; after each timeout RTO doubles (up to max), so a peer
//   that is slow or gone is not flooded with requests.

namespace cvslam::coop {

struct RequestTimeoutOptions {
  double min_s = 0.5;  ///< floor, and the timeout before any round trip was measured [s]
  double max_s = 2.0;  ///< ceiling of the timeout and of its back-off [s]
};

class RequestTimeout {
 public:
  explicit RequestTimeout(const RequestTimeoutOptions& options = {})
      : o_(options), rto_s_(options.min_s) {}

  /// The current timeout [s].
  double seconds() const { return rto_s_; }
  /// An answer came `round_trip_s` after its request.
  void onAnswer(double round_trip_s);
  /// The request timed out: back off.
  void onTimeout();
  /// Smoothed round trip [s]; negative before the first answer.
  double smoothedRoundTrip() const { return srtt_s_; }

 private:
  RequestTimeoutOptions o_;
  double rto_s_;
  double srtt_s_ = -1.0;
  double rttvar_s_ = 0.0;
};

}  // namespace cvslam::coop
