// DcCooperation's inbound side (dc_cooperation.h): each message is validated when it arrives
// (finite, sane sizes and magnitudes, not from self) and queued for afterFrame.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>

#include "cvslam/coop/dc_cooperation.h"

namespace cvslam::coop {

namespace {
/// Descriptors longer than this are not descriptors (SIFT: 128 bytes) [bytes].
constexpr std::size_t kMaxDescriptorBytes = 1024;
/// Relative asymmetry tolerated in a received covariance (rounding of the sender's algebra).
constexpr double kSymmetryTolerance = 1e-6;

bool validHeader(const CoopHeader& h) {
  return h.agent_id >= 1 && h.seq >= 0 && h.t_us >= 0;
}

}  // namespace

bool DcCooperation::enqueue(Inbound message) {
  if (static_cast<int>(inbox_.size()) >= o_.max_queued_messages) {
    inbox_.pop_front();
    ++stats_.rejected_queue_full;
  }
  inbox_.push_back(std::move(message));
  return true;
}

bool DcCooperation::onSummary(const CoopSummary& m) {
  if (m.header.agent_id == self_) return ++stats_.rejected_not_for_me, false;
  const bool ok = validHeader(m.header) && m.mean.allFinite() && m.std.allFinite() &&
                  m.mean.norm() <= o_.max_position_m && (m.std.array() >= 0.0).all() &&
                  m.std.maxCoeff() <= o_.max_position_m && m.num_features >= 0 &&
                  std::isfinite(m.vehicle_cov_trace) && m.vehicle_cov_trace >= 0.0;
  if (!ok) return ++stats_.rejected_invalid, false;
  return enqueue(m);
}

bool DcCooperation::onIndex(const FeatureIndexList& m) {
  if (m.header.agent_id == self_) return ++stats_.rejected_not_for_me, false;
  if (!validHeader(m.header) || static_cast<int>(m.indices.size()) > o_.max_indices_per_message)
    return ++stats_.rejected_invalid, false;
  return enqueue(m);
}

bool DcCooperation::onRequest(const SharedRequest& m) {
  if (m.header.agent_id == self_ || m.to_agent != self_) return ++stats_.rejected_not_for_me, false;
  if (!validHeader(m.header) || static_cast<int>(m.indices.size()) > o_.max_landmarks_per_message)
    return ++stats_.rejected_invalid, false;
  return enqueue(m);
}

bool DcCooperation::onShared(const SharedLandmarks& m) {
  if (m.header.agent_id == self_ || m.to_agent != self_) return ++stats_.rejected_not_for_me, false;
  bool ok = validHeader(m.header) &&
            static_cast<int>(m.landmarks.size()) <= o_.max_landmarks_per_message &&
            std::isfinite(m.vehicle_cov_trace) && m.vehicle_cov_trace >= 0.0;
  // Provenance: ascending ids ≥ 1 that name the sender, or empty (unknown).
  const std::vector<int>& from = m.informed_by;
  ok = ok && static_cast<int>(from.size()) <= o_.max_peers + 1 &&
       std::adjacent_find(from.begin(), from.end(), std::greater_equal<int>()) == from.end() &&
       (from.empty() ||
        (from.front() >= 1 && std::binary_search(from.begin(), from.end(), m.header.agent_id)));
  for (const SharedLandmark& l : m.landmarks) {
    if (!ok) break;
    ok = l.p_LinN.allFinite() && l.p_LinN.norm() <= o_.max_position_m && l.covariance.allFinite() &&
         l.descriptor.size() <= kMaxDescriptorBytes;
    if (!ok) break;
    const double scale = l.covariance.cwiseAbs().maxCoeff();
    ok = (l.covariance - l.covariance.transpose()).cwiseAbs().maxCoeff() <=
         kSymmetryTolerance * scale;
    if (!ok) break;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(l.covariance, Eigen::EigenvaluesOnly);
    ok = eig.eigenvalues().minCoeff() >= o_.min_landmark_variance_m2 &&
         eig.eigenvalues().maxCoeff() <= o_.max_landmark_variance_m2;
  }
  if (ok && m.joint_covariance.size() > 0) ok = validJointCovariance(m);
  if (!ok) return ++stats_.rejected_invalid, false;
  return enqueue(m);
}

bool DcCooperation::validJointCovariance(const SharedLandmarks& m) const {
  const Eigen::MatrixXd& J = m.joint_covariance;
  const auto n = static_cast<Eigen::Index>(m.landmarks.size());
  if (J.rows() != 3 * n || J.cols() != 3 * n || !J.allFinite()) return false;
  const double scale = J.cwiseAbs().maxCoeff();
  if ((J - J.transpose()).cwiseAbs().maxCoeff() > kSymmetryTolerance * scale) return false;
  for (Eigen::Index i = 0; i < n; ++i)
    if ((J.block<3, 3>(3 * i, 3 * i) - m.landmarks[static_cast<std::size_t>(i)].covariance)
            .cwiseAbs()
            .maxCoeff() > kSymmetryTolerance * scale)
      return false;
  return Eigen::LLT<Eigen::MatrixXd>(J).info() == Eigen::Success;
}

}  // namespace cvslam::coop
