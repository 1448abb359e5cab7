// DcCooperation in estimated frames (dc_cooperation.h, docs/merge.md): the place exchange's
// landmarks, the geometric verification of a peer's frame and the relation book, carrying a
// peer's landmarks and ellipsoid into the own frame, and the team frame.

#include <algorithm>
#include <cmath>
#include <optional>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "dc_cooperation_detail.h"

namespace cvslam::coop {

using detail::kUsPerS;
using detail::seconds;

namespace {
/// The state variable of own landmark `id`: in the state, or held there (a Schmidt variable).
std::optional<VariableKey> stateKeyOf(const VisualInertialSlam& slam, int64_t id) {
  const auto key = static_cast<uint64_t>(id);
  if (slam.state().find(VariableKey::landmark(key)) != nullptr) return VariableKey::landmark(key);
  if (slam.state().find(VariableKey::heldLandmark(key)) != nullptr)
    return VariableKey::heldLandmark(key);
  return std::nullopt;
}
}  // namespace

bool DcCooperation::framesShared(int peer) const {
  if (!o_.frames_given) return false;
  const auto it = peers_.find(peer);
  return it == peers_.end() || !it->second.summary.own_frame;
}

std::optional<merge::FrameRelation> DcCooperation::relationOf(int peer) const {
  if (framesShared(peer)) return merge::FrameRelation{};
  return relations_.relation(peer);
}

Eigen::Matrix<double, 9, 1> TeamFrame::apply(const Eigen::Matrix<double, 9, 1>& x_own) const {
  Eigen::Matrix<double, 9, 1> x = x_own;
  x.head<3>() = own_in_root.apply(x_own.head<3>());
  x(8) = wrapAngle(x_own(8) + own_in_root.yaw());
  return x;
}

TeamFrame DcCooperation::teamFrame() const {
  TeamFrame f;
  f.root = self_;
  std::vector<int> related = relations_.adoptedPeers();
  for (int j : peers())
    if (framesShared(j)) related.push_back(j);
  // The team's given frame, when this agent or a related peer estimates in it, is the team
  // frame (its lowest id names it); else the lowest id's own frame (docs/merge.md).
  std::optional<int> given;
  if (o_.frames_given) given = self_;
  for (int j : related) {
    f.merged = true;
    f.root = std::min(f.root, j);
    const auto peer = peers_.find(j);
    if (peer != peers_.end() && !peer->second.summary.own_frame)
      given = std::min(given.value_or(j), j);
  }
  if (given) f.root = *given;
  if (f.root != self_) f.own_in_root = relationOf(f.root)->inverse();
  return f;
}

bool DcCooperation::teamState(const Eigen::Matrix<double, 9, 1>& x_own, int* root,
                              Eigen::Matrix<double, 9, 1>* x_team) const {
  if (o_.frames_given) return false;
  const TeamFrame team = teamFrame();
  if (!team.merged) return false;
  *root = team.root;
  *x_team = team.apply(x_own);
  return true;
}

std::vector<RelationRecord> DcCooperation::takeRelationRecords() {
  std::vector<RelationRecord> out;
  out.swap(relation_records_);
  return out;
}

std::vector<StateLandmark> DcCooperation::placeLandmarks(const VisualInertialSlam& slam,
                                                         const std::vector<uint32_t>& indices) {
  std::vector<StateLandmark> out;
  for (const StateLandmark& l : slam.stateLandmarks())
    if (std::binary_search(indices.begin(), indices.end(), l.index)) out.push_back(l);
  std::vector<int64_t> archived;
  for (uint32_t index : indices) {
    const std::vector<int64_t>& ids = slam.archive().withIndex(index);
    archived.insert(archived.end(), ids.begin(), ids.end());
  }
  std::sort(archived.begin(), archived.end());  // by id, as the state's
  archived.erase(std::unique(archived.begin(), archived.end()), archived.end());
  for (int64_t id : archived) {
    const ArchivedLandmark* a = slam.archive().find(id);
    StateLandmark l;
    l.id = id;
    l.index = a->index;
    l.p_LinN = a->p_LinN;
    l.covariance = a->covariance;
    l.descriptor = a->descriptor;
    l.last_seen_us = a->last_seen_us;
    // A held landmark as the state holds it now (a Schmidt variable, with its correlations).
    if (const StateVariable* v =
            slam.state().find(VariableKey::heldLandmark(static_cast<uint64_t>(id)))) {
      l.p_LinN = slam.state().value(*v);
      l.covariance = slam.state().covarianceOf(*v);
    }
    out.push_back(std::move(l));
  }
  return out;
}

std::vector<DcCooperation::Correspondence> DcCooperation::correspondences(
    const SharedLandmarks& m, const std::vector<StateLandmark>& local) const {
  std::vector<Correspondence> out;
  std::vector<bool> used(local.size(), false);
  for (std::size_t k = 0; k < m.landmarks.size(); ++k) {
    const SharedLandmark& s = m.landmarks[k];
    for (std::size_t i = 0; i < local.size(); ++i) {
      if (used[i] || local[i].index != s.index ||
          !descriptorsAgree(local[i].descriptor, s.descriptor))
        continue;
      used[i] = true;
      out.push_back({k, &local[i], s.index});
      break;
    }
  }
  return out;
}

void DcCooperation::verifyRelation(const SharedLandmarks& m,
                                   const std::vector<Correspondence>& matched,
                                   const VisualInertialSlam& slam, int64_t now_us) {
  const int j = m.header.agent_id;
  RelationRecord r;
  r.t_us = now_us;
  r.peer = j;
  r.correspondences = static_cast<int>(matched.size());
  ++stats_.verifications;
  // The own points with their joint covariance (from the state); the peer's with the sender's
  // joint covariance, or the bound blockdiag(n·P_i) on it (fuseConfirmed says why).
  merge::AlignmentPoints points;
  const auto n = static_cast<Eigen::Index>(matched.size());
  const bool joint = m.joint_covariance.rows() == 3 * static_cast<Eigen::Index>(m.landmarks.size());
  points.cov_b = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const Correspondence& c = matched[static_cast<std::size_t>(k)];
    points.a.push_back(c.own->p_LinN);
    points.b.push_back(m.landmarks[c.peer].p_LinN);
    for (Eigen::Index l = 0; l < n; ++l) {
      if (!joint && l != k) continue;
      const auto row = static_cast<Eigen::Index>(3 * c.peer);
      const auto col = static_cast<Eigen::Index>(3 * matched[static_cast<std::size_t>(l)].peer);
      points.cov_b.block<3, 3>(3 * k, 3 * l) =
          joint ? Eigen::Matrix3d(m.joint_covariance.block<3, 3>(row, col))
                : Eigen::Matrix3d(static_cast<double>(n) * m.landmarks[c.peer].covariance);
    }
  }
  Expected<merge::FourDofAlignment> a = Status::Error("no landmark in common");
  if (n > 0) {
    points.cov_a = ownJointCovariance(matched, slam);
    a = aligner_.align(points);
  }
  const bool merged = relations_.relation(j).has_value();
  PeerState& peer = peers_[j];
  if (!merged) {
    // Not merged: consecutive failures put the next place request off, doubling the wait.
    peer.place_failures = a.ok() ? 0 : peer.place_failures + 1;
    const double wait_s =
        a.ok()
            ? 0.0
            : std::min(o_.max_place_backoff_s,
                       o_.place_period_s * std::ldexp(1.0, std::min(peer.place_failures, 30) - 1));
    peer.next_place_request_us = now_us + static_cast<int64_t>(std::llround(wait_s * kUsPerS));
  }
  if (!a.ok()) {
    ++stats_.verifications_failed;
    r.verdict = "failed";
    r.reason = a.status().message();
    relation_records_.push_back(std::move(r));
    return;
  }
  r.inliers = static_cast<int>(a->inliers.size());
  r.candidate = a->relation;
  const merge::RelationDecision d =
      relations_.offer(j, {a->relation, static_cast<double>(now_us) / kUsPerS, r.inliers});
  r.verdict = merge::relationVerdictName(d.verdict);
  r.reason = d.reason;
  r.nis = d.nis;
  if (d.verdict == merge::RelationVerdict::kAdopted) ++stats_.relations_adopted;
  if (d.verdict == merge::RelationVerdict::kRefined) ++stats_.relations_refined;
  if (d.verdict == merge::RelationVerdict::kRejected) ++stats_.relations_rejected;
  relation_records_.push_back(std::move(r));
}

std::optional<Eigen::MatrixXd> DcCooperation::exactJointCovariance(
    const std::vector<Correspondence>& own, const VisualInertialSlam& slam) {
  std::vector<VariableKey> keys;
  for (const Correspondence& c : own) {
    const std::optional<VariableKey> key = stateKeyOf(slam, c.own->id);
    if (!key) return std::nullopt;
    keys.push_back(*key);
  }
  Expected<Eigen::MatrixXd> J = CovarianceHelper::marginalCovariance(slam.state(), keys);
  if (!J.ok()) return std::nullopt;
  return std::move(J.value());
}

Eigen::MatrixXd DcCooperation::ownJointCovariance(const std::vector<Correspondence>& own,
                                                  const VisualInertialSlam& slam) {
  // Archived landmarks keep their marginals only, correlated in unknown ways with each other
  // and with the state: the landmarks in the state form one group (their joint covariance),
  // every other landmark its own group, and with g groups blockdiag(g·group) bounds the joint
  // covariance whatever the correlations (covariance intersection with equal weights; g = 1,
  // the exact joint covariance, when all are in the state).
  std::vector<std::size_t> in_state;
  std::vector<VariableKey> keys;
  for (std::size_t k = 0; k < own.size(); ++k) {
    const std::optional<VariableKey> key = stateKeyOf(slam, own[k].own->id);
    if (!key) continue;
    in_state.push_back(k);
    keys.push_back(*key);
  }
  Expected<Eigen::MatrixXd> S = CovarianceHelper::marginalCovariance(slam.state(), keys);
  if (!S.ok()) in_state.clear();
  const auto n = static_cast<Eigen::Index>(own.size());
  const double groups =
      static_cast<double>(own.size() - in_state.size() + (in_state.empty() ? 0 : 1));
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (Eigen::Index k = 0; k < n; ++k)
    C.block<3, 3>(3 * k, 3 * k) = groups * own[static_cast<std::size_t>(k)].own->covariance;
  for (std::size_t a = 0; a < in_state.size(); ++a)
    for (std::size_t b = 0; b < in_state.size(); ++b)
      C.block<3, 3>(3 * static_cast<Eigen::Index>(in_state[a]),
                    3 * static_cast<Eigen::Index>(in_state[b])) =
          groups *
          S->block<3, 3>(3 * static_cast<Eigen::Index>(a), 3 * static_cast<Eigen::Index>(b));
  return C;
}

SharedLandmarks DcCooperation::inOwnFrame(const SharedLandmarks& m, const merge::FrameRelation& r) {
  SharedLandmarks out = m;
  const auto n = static_cast<Eigen::Index>(m.landmarks.size());
  const Eigen::Matrix3d R = r.rotation();
  // Stacked Jacobians: every point moves with the one relation, so its uncertainty correlates
  // them all (J_x P J_xᵀ over the whole set).
  Eigen::MatrixXd J_x(3 * n, 4);
  for (Eigen::Index k = 0; k < n; ++k) {
    SharedLandmark& l = out.landmarks[static_cast<std::size_t>(k)];
    merge::FrameRelation::Matrix34d J;
    l.p_LinN = r.apply(m.landmarks[static_cast<std::size_t>(k)].p_LinN, &J);
    l.covariance = R * l.covariance * R.transpose() + J * r.P * J.transpose();
    J_x.middleRows<3>(3 * k) = J;
  }
  if (m.joint_covariance.rows() == 3 * n) {
    Eigen::MatrixXd rotated = m.joint_covariance;
    for (Eigen::Index k = 0; k < n; ++k) {
      rotated.middleRows<3>(3 * k) = R * rotated.middleRows<3>(3 * k);
    }
    for (Eigen::Index k = 0; k < n; ++k) {
      rotated.middleCols<3>(3 * k) = rotated.middleCols<3>(3 * k) * R.transpose();
    }
    out.joint_covariance = rotated + J_x * r.P * J_x.transpose();
  }
  return out;
}

FeatureEllipsoid DcCooperation::inOwnFrame(const FeatureEllipsoid& e,
                                           const merge::FrameRelation& r) {
  FeatureEllipsoid out = e;
  merge::FrameRelation::Matrix34d J;
  out.mean = r.apply(e.mean, &J);
  // The axis-aligned ellipsoid with the rotated one's extent along each axis (the overlap
  // test is axis-aligned), widened by the relation's uncertainty.
  const Eigen::Matrix3d R = r.rotation();
  const Eigen::Matrix3d C =
      R * e.std.array().square().matrix().asDiagonal() * R.transpose() + J * r.P * J.transpose();
  out.std = C.diagonal().cwiseSqrt();
  return out;
}

bool DcCooperation::placeDue(int peer, int n_self, int64_t now_us) {
  // Not merged: the place descriptor, every place_period_s (the peer asks, handleIndex).
  auto last = last_place_us_.find(peer);
  if (n_self == 0 ||
      (last != last_place_us_.end() && seconds(now_us - last->second) < o_.place_period_s))
    return false;
  last_place_us_[peer] = now_us;
  return true;
}

}  // namespace cvslam::coop
