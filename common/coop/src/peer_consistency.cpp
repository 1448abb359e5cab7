#include "cvslam/coop/peer_consistency.h"

#include <algorithm>

#include "cvslam/filter/chi_square.h"

namespace cvslam::coop {

double PeerConsistency::add(double nis, int dof) {
  if (o_.window <= 0 || dof <= 0 || !(nis >= 0.0)) return scale();
  window_.push_back({nis, dof});
  while (static_cast<int>(window_.size()) > o_.window) window_.pop_front();
  return scale();
}

double PeerConsistency::scale() const {
  double nis = 0.0;
  int dof = 0;
  for (const Exchange& e : window_) nis += e.nis, dof += e.dof;
  if (dof == 0 || nis <= chiSquareQuantile(o_.probability, dof)) return 1.0;
  return std::max(1.0, nis / dof);
}

}  // namespace cvslam::coop
