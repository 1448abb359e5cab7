#include "cvslam/coop/dc_cooperation.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/geometry/euler.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam::coop {

namespace {
enum Stream : int { kSummaryStream = 0, kIndexStream = 1, kRequestStream = 2, kSharedStream = 3 };
constexpr double kUsPerS = 1e6;
constexpr int kLandmarkDof = 3;

double seconds(int64_t dt_us) {
  return static_cast<double>(dt_us) / kUsPerS;
}

double vehiclePositionTrace(const VisualInertialSlam& slam) {
  return slam.vehicleCovariance().topLeftCorner<3, 3>().trace();
}

/// In-state landmarks observed in the current frame (the features the agent observes now).
std::vector<StateLandmark> observedNow(const std::vector<StateLandmark>& in_state, int64_t t_us) {
  std::vector<StateLandmark> out;
  for (const StateLandmark& l : in_state)
    if (l.last_seen_us == t_us) out.push_back(l);
  return out;
}
}  // namespace

DcCooperation::DcCooperation(int self_id, const DcCooperationOptions& options, int64_t boot_id)
    : self_(self_id),
      o_(options),
      boot_id_(boot_id),
      informed_by_{self_id},
      aligner_(options.aligner),
      relations_(options.relations) {}

std::optional<merge::FrameRelation> DcCooperation::relationOf(int peer) const {
  if (o_.frames_given) return merge::FrameRelation{};
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
  if (o_.frames_given) related = peers();
  for (int j : related) {
    f.merged = true;
    f.root = std::min(f.root, j);
  }
  if (f.root != self_) f.own_in_root = relationOf(f.root)->inverse();
  return f;
}

std::vector<RelationRecord> DcCooperation::takeRelationRecords() {
  std::vector<RelationRecord> out;
  out.swap(relation_records_);
  return out;
}

bool DcCooperation::independentOf(const std::vector<int>& informed_by) const {
  if (informed_by.empty()) return false;  // unknown provenance
  for (int id : informed_by)
    if (std::binary_search(informed_by_.begin(), informed_by_.end(), id)) return false;
  return true;
}

std::vector<CoopEvent> DcCooperation::takeEvents() {
  std::vector<CoopEvent> out;
  out.swap(events_);
  return out;
}

std::vector<int> DcCooperation::peers() const {
  std::vector<int> out;
  for (const auto& [id, p] : peers_) out.push_back(id);
  return out;
}

bool DcCooperation::admit(int stream, const CoopHeader& h, int64_t now_us) {
  if (seconds(now_us - h.t_us) > o_.max_message_age_s) return ++stats_.rejected_stale, false;
  auto it = peers_.find(h.agent_id);
  if (it == peers_.end()) return ++stats_.rejected_unknown_peer, false;
  PeerState& p = it->second;
  auto last = p.last_seq.find(stream);
  if (last != p.last_seq.end()) {
    if (h.seq == last->second) return ++stats_.rejected_duplicate, false;
    if (h.seq < last->second) return ++stats_.rejected_reordered, false;
  }
  p.last_seq[stream] = h.seq;
  p.last_heard_us = std::max(p.last_heard_us, h.t_us);
  return true;
}

CoopHeader DcCooperation::nextHeader(int stream, int64_t t_us) {
  CoopHeader h;
  h.agent_id = self_;
  h.t_us = t_us;
  h.seq = next_seq_[stream]++;
  return h;
}

void DcCooperation::handleSummary(const CoopSummary& m, int64_t now_us) {
  if (seconds(now_us - m.header.t_us) > o_.max_message_age_s) {
    ++stats_.rejected_stale;
    return;
  }
  const int j = m.header.agent_id;
  auto it = peers_.find(j);
  if (it == peers_.end() && static_cast<int>(peers_.size()) >= o_.max_peers) {
    ++stats_.rejected_too_many_peers;
    return;
  }
  if (it == peers_.end() || it->second.boot_id != m.boot_id) {
    const bool restart = it != peers_.end();
    PeerState fresh;
    fresh.boot_id = m.boot_id;
    fresh.last_heard_us = m.header.t_us;
    fresh.timeout = RequestTimeout({o_.min_request_timeout_s, o_.request_timeout_s});
    fresh.consistency = PeerConsistency(o_.consistency);
    peers_[j] = fresh;
    if (restart) {
      ++stats_.peer_restarts;
      relations_.forget(j);  // a restarted peer estimates in a new frame
      last_place_us_.erase(j);
    }
    CoopEvent e;
    e.t_us = now_us;
    e.kind = restart ? CoopEventKind::kPeerRestarted : CoopEventKind::kPeerJoined;
    e.peer = j;
    events_.push_back(e);
  }
  if (!admit(kSummaryStream, m.header, now_us)) return;
  ++stats_.summaries_received;
  peers_[j].summary = m;
}

void DcCooperation::handleIndex(const FeatureIndexList& m, const VisualInertialSlam& slam,
                                const StereoFrameObservations& frame, CoopOutbox* out) {
  const int64_t now_us = frame.t_us;
  if (!admit(kIndexStream, m.header, now_us)) return;
  ++stats_.indices_received;
  PeerState& p = peers_[m.header.agent_id];
  if (p.request_pending) return;  // one exchange at a time per peer
  // A peer not yet merged: its INDEX is a place descriptor. The higher id of the two asks (one
  // exchange per pair; with both_ways each side verifies), and only for landmarks it has
  // mapped, the ones a verification can use.
  const bool merged = relationOf(m.header.agent_id).has_value();
  std::vector<uint32_t> sorted = m.indices;
  std::sort(sorted.begin(), sorted.end());
  if (!merged) {
    // A place descriptor (the peer's local map): ask for the landmarks of it that this agent
    // mapped, in its state or its archive (the peer may fly where this agent flew before).
    std::vector<StateLandmark> known = placeLandmarks(slam);
    SharedRequest r;
    for (const StateLandmark& l : known)
      if (std::binary_search(sorted.begin(), sorted.end(), l.index)) r.indices.push_back(l.index);
    std::sort(r.indices.begin(), r.indices.end());
    r.indices.erase(std::unique(r.indices.begin(), r.indices.end()), r.indices.end());
    if (static_cast<int>(r.indices.size()) < o_.aligner.min_inliers) return;  // cannot verify
    if (static_cast<int>(r.indices.size()) > o_.max_landmarks_per_message)
      r.indices.resize(static_cast<std::size_t>(o_.max_landmarks_per_message));
    sendRequest(m.header.agent_id, std::move(r), now_us, out);
    return;
  }
  // Candidates: in-state landmarks with an index the peer observes, most recently seen first;
  // then (map_shared_landmarks) the points observed now and not mapped.
  std::vector<StateLandmark> cand;
  for (const StateLandmark& l : slam.stateLandmarks())
    if (std::binary_search(sorted.begin(), sorted.end(), l.index)) cand.push_back(l);
  std::stable_sort(cand.begin(), cand.end(), [](const StateLandmark& a, const StateLandmark& b) {
    return a.last_seen_us > b.last_seen_us;
  });
  if (o_.map_shared_landmarks && slam.time() == now_us) {
    for (const StereoObservation& obs : frame.observations) {
      if (!std::binary_search(sorted.begin(), sorted.end(), obs.index) || !slam.isUnmapped(obs))
        continue;
      StateLandmark l;
      l.index = obs.index;
      cand.push_back(l);
    }
  }
  if (cand.empty()) return;
  SharedRequest r;
  for (const StateLandmark& l : cand) {
    if (static_cast<int>(r.indices.size()) >= o_.max_landmarks_per_message) break;
    r.indices.push_back(l.index);
  }
  std::sort(r.indices.begin(), r.indices.end());
  r.indices.erase(std::unique(r.indices.begin(), r.indices.end()), r.indices.end());
  sendRequest(m.header.agent_id, std::move(r), now_us, out);
}

void DcCooperation::sendRequest(int peer, SharedRequest r, int64_t now_us, CoopOutbox* out) {
  PeerState& p = peers_[peer];
  r.header = nextHeader(kRequestStream, now_us);
  r.to_agent = peer;
  p.request_pending = true;
  p.request_sent_us = now_us;
  p.requested = r.indices;
  ++stats_.requests_sent;
  events_.push_back({now_us, CoopEventKind::kRequestSent, r.to_agent,
                     static_cast<int>(r.indices.size()), 0, 0, 0, 1.0});
  out->requests.push_back(std::move(r));
}

std::vector<StateLandmark> DcCooperation::placeLandmarks(const VisualInertialSlam& slam) {
  std::vector<StateLandmark> out = slam.stateLandmarks();
  std::vector<std::pair<int64_t, const ArchivedLandmark*>> archived;
  for (const auto& [id, a] : slam.archive().all()) archived.emplace_back(id, &a);
  std::sort(archived.begin(), archived.end());  // deterministic (the archive is unordered)
  for (const auto& [id, a] : archived) {
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

void DcCooperation::handleRequest(const SharedRequest& m, const VisualInertialSlam& slam,
                                  int64_t now_us, CoopOutbox* out) {
  if (!admit(kRequestStream, m.header, now_us)) return;
  ++stats_.requests_received;
  std::vector<uint32_t> wanted = m.indices;
  std::sort(wanted.begin(), wanted.end());
  SharedLandmarks s;
  s.header = nextHeader(kSharedStream, now_us);
  s.to_agent = m.header.agent_id;
  s.vehicle_cov_trace = vehiclePositionTrace(slam);
  s.informed_by = informed_by_;
  std::vector<VariableKey> keys;
  std::vector<int64_t> ids;
  for (const StateLandmark& l : slam.stateLandmarks()) {
    if (static_cast<int>(s.landmarks.size()) >= o_.max_landmarks_per_message) break;
    if (!std::binary_search(wanted.begin(), wanted.end(), l.index)) continue;
    s.landmarks.push_back({l.index, l.p_LinN, l.covariance, l.descriptor});
    keys.push_back(VariableKey::landmark(static_cast<uint64_t>(l.id)));
    ids.push_back(l.id);
  }
  // Then the archived landmarks offered lately (offer_archived) with a wanted index: a held
  // one as the state holds it now (a Schmidt variable, with its correlations), any other with
  // the mean and marginal covariance it left the state with (landmark_archive.h).
  bool marginal_only = false;
  for (const auto& [id, t] : offered_) {
    if (static_cast<int>(s.landmarks.size()) >= o_.max_landmarks_per_message) break;
    const ArchivedLandmark* a = slam.archive().find(id);
    if (a == nullptr || !std::binary_search(wanted.begin(), wanted.end(), a->index)) continue;
    SharedLandmark l{a->index, a->p_LinN, a->covariance, a->descriptor};
    const VariableKey held = VariableKey::heldLandmark(static_cast<uint64_t>(id));
    if (const StateVariable* v = slam.state().find(held)) {
      l.p_LinN = slam.state().value(*v);
      l.covariance = slam.state().covarianceOf(*v);
      keys.push_back(held);
    } else {
      marginal_only = true;
    }
    s.landmarks.push_back(std::move(l));
    ids.push_back(id);
  }
  recordSent(s.header.seq, std::move(ids));
  // The joint covariance, so that the receiver need not bound the correlations; not when an
  // archived landmark kept its marginal only (the receiver then bounds them all).
  if (Expected<Eigen::MatrixXd> J = CovarianceHelper::marginalCovariance(slam.state(), keys);
      !marginal_only && J.ok() && s.landmarks.size() >= 2)
    s.joint_covariance = std::move(J.value());
  ++stats_.shared_sent;
  events_.push_back({now_us, CoopEventKind::kSharedSent, s.to_agent,
                     static_cast<int>(s.landmarks.size()), 0, 0, 0, 1.0});
  out->shared.push_back(std::move(s));
}

void DcCooperation::handleShared(const SharedLandmarks& m, VisualInertialSlam& slam,
                                 const StereoFrameObservations& frame, CoopOutbox* out) {
  const int64_t now_us = frame.t_us;
  if (!admit(kSharedStream, m.header, now_us)) return;
  ++stats_.shared_received;
  const int j = m.header.agent_id;
  PeerState& p = peers_[j];
  // The answer to the pending request holds only requested indices; anything else is a
  // both_ways return of an exchange the peer started (fused, never returned again).
  bool answers_request = p.request_pending;
  for (const SharedLandmark& l : m.landmarks)
    answers_request =
        answers_request && std::binary_search(p.requested.begin(), p.requested.end(), l.index);
  if (answers_request) {
    p.request_pending = false;
    p.timeout.onAnswer(seconds(now_us - p.request_sent_us));
  }

  std::vector<StateLandmark> local = slam.stateLandmarks();
  CoopEvent e;
  e.t_us = now_us;
  e.kind = CoopEventKind::kFused;
  e.peer = j;
  e.count = static_cast<int>(m.landmarks.size());
  if (o_.frames_given) {
    const bool independent = o_.use_provenance && independentOf(m.informed_by);
    const std::vector<ConfirmedPair> pairs = confirm(m, slam, frame, independent, &local, &e);
    if (!pairs.empty() &&
        !fuseConfirmed(m, pairs, local, answers_request, independent, slam, now_us, out, &e))
      return;
    events_.push_back(e);
    return;
  }
  // Estimated frames: carried with the relation adopted before this message (not yet
  // refined by it), then verified again.
  const std::optional<merge::FrameRelation> relation = relations_.relation(j);
  const std::vector<StateLandmark> place = placeLandmarks(slam);
  const std::vector<Correspondence> matched = correspondences(m, place);
  verifyRelation(m, matched, slam, now_us);
  if (!relation) {
    ++stats_.skipped_unmerged;
    if (o_.both_ways && answers_request) returnOwnEstimates(j, matched, nullptr, slam, now_us, out);
    return;
  }
  const SharedLandmarks carried = inOwnFrame(m, *relation);
  const std::vector<ConfirmedPair> pairs = confirm(carried, slam, frame, false, &local, &e);
  if (!pairs.empty() &&
      !fuseConfirmed(carried, pairs, local, answers_request, false, slam, now_us, out, &e))
    return;
  events_.push_back(e);
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
    const auto id = static_cast<uint64_t>(c.own->id);
    if (slam.state().find(VariableKey::landmark(id)) != nullptr)
      keys.push_back(VariableKey::landmark(id));
    else if (slam.state().find(VariableKey::heldLandmark(id)) != nullptr)
      keys.push_back(VariableKey::heldLandmark(id));
    else
      return std::nullopt;
  }
  Expected<Eigen::MatrixXd> J = CovarianceHelper::marginalCovariance(slam.state(), keys);
  if (!J.ok()) return std::nullopt;
  return std::move(J.value());
}

Eigen::MatrixXd DcCooperation::ownJointCovariance(const std::vector<Correspondence>& own,
                                                  const VisualInertialSlam& slam) {
  if (std::optional<Eigen::MatrixXd> J = exactJointCovariance(own, slam)) return std::move(*J);
  // Archived landmarks keep their marginals only, correlated in unknown ways with each other
  // and with the state: the landmarks in the state form one group (their joint covariance),
  // every other landmark its own group, and with g groups blockdiag(g·group) bounds the joint
  // covariance whatever the correlations (covariance intersection with equal weights).
  std::vector<std::size_t> in_state;
  std::vector<VariableKey> keys;
  for (std::size_t k = 0; k < own.size(); ++k) {
    const auto id = static_cast<uint64_t>(own[k].own->id);
    VariableKey key = VariableKey::landmark(id);
    if (slam.state().find(key) == nullptr) key = VariableKey::heldLandmark(id);
    if (slam.state().find(key) == nullptr) continue;
    in_state.push_back(k);
    keys.push_back(key);
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

void DcCooperation::returnOwnEstimates(int peer, const std::vector<Correspondence>& own,
                                       const Eigen::MatrixXd* joint, const VisualInertialSlam& slam,
                                       int64_t now_us, CoopOutbox* out) {
  if (own.empty()) return;
  SharedLandmarks back;
  back.header = nextHeader(kSharedStream, now_us);
  back.to_agent = peer;
  back.vehicle_cov_trace = vehiclePositionTrace(slam);
  back.informed_by = informed_by_;
  std::vector<int64_t> ids;
  for (const Correspondence& c : own) {
    back.landmarks.push_back({c.index, c.own->p_LinN, c.own->covariance, c.own->descriptor});
    ids.push_back(c.own->id);
  }
  // Only an exact joint covariance is sent (a bound would fail the receiver's check that its
  // diagonal blocks are the landmarks' covariances); without one the receiver bounds it.
  if (own.size() >= 2) {
    if (joint != nullptr) {
      back.joint_covariance = *joint;
    } else if (std::optional<Eigen::MatrixXd> J = exactJointCovariance(own, slam)) {
      back.joint_covariance = std::move(*J);
    }
  }
  recordSent(back.header.seq, std::move(ids));
  ++stats_.shared_sent;
  events_.push_back({now_us, CoopEventKind::kSharedSent, peer,
                     static_cast<int>(back.landmarks.size()), 0, 0, 0, 1.0});
  out->shared.push_back(std::move(back));
}

std::vector<DcCooperation::ConfirmedPair> DcCooperation::confirm(
    const SharedLandmarks& m, VisualInertialSlam& slam, const StereoFrameObservations& frame,
    bool independent, std::vector<StateLandmark>* local_in, CoopEvent* e) {
  const std::vector<StateLandmark>& local = *local_in;
  const double gate = chiSquareQuantile(o_.gate_probability, kLandmarkDof);
  std::vector<bool> used(local.size(), false);
  std::vector<ConfirmedPair> pairs;
  // Shared landmarks matched to an unmapped observation (mapped below), and those observations.
  StereoFrameObservations to_map;
  to_map.t_us = frame.t_us;
  std::vector<const SharedLandmark*> mapped_for;
  std::vector<bool> taken(frame.observations.size(), false);
  const bool may_map = o_.map_shared_landmarks && slam.time() == frame.t_us;
  for (const SharedLandmark& s : m.landmarks) {
    bool any_index = false, any_descriptor = false;
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = local.size();
    for (std::size_t i = 0; i < local.size(); ++i) {
      if (used[i] || local[i].index != s.index) continue;
      any_index = true;
      if (!descriptorsAgree(local[i].descriptor, s.descriptor)) continue;
      any_descriptor = true;
      const double d2 =
          pairNis(s.p_LinN - local[i].p_LinN, local[i].covariance, s.covariance, independent);
      if (d2 <= gate && d2 < best) best = d2, best_i = i;
    }
    if (!any_index && may_map) {
      if (const int k = matchUnmapped(s, slam, frame, independent, gate, taken); k >= 0) {
        taken[static_cast<std::size_t>(k)] = true;
        to_map.observations.push_back(frame.observations[static_cast<std::size_t>(k)]);
        mapped_for.push_back(&s);
        continue;
      }
    }
    if (!any_index) {
      ++stats_.shared_not_in_state;
      ++e->not_in_state;
    } else if (!any_descriptor) {
      ++stats_.rejected_descriptor;
      ++e->rejected_descriptor;
    } else if (best_i == local.size()) {
      ++stats_.rejected_gate;
      ++e->rejected_gate;
    } else {
      used[best_i] = true;
      pairs.push_back({best_i, &s});
    }
  }
  if (to_map.observations.empty()) return pairs;
  // Map the matched points (as step 5 of the filter would, with their own stereo observation),
  // then pair them with the peer's estimates like in-state landmarks.
  std::vector<int64_t> ids;
  if (!slam.mapObservations(to_map, &ids).ok()) return pairs;
  std::vector<int64_t> paired_ids;
  for (const ConfirmedPair& pr : pairs) paired_ids.push_back(local[pr.local].id);
  *local_in = slam.stateLandmarks();  // sorted by id
  const auto position = [&](int64_t id) {
    auto it =
        std::lower_bound(local_in->begin(), local_in->end(), id,
                         [](const StateLandmark& l, int64_t wanted) { return l.id < wanted; });
    return it != local_in->end() && it->id == id ? static_cast<std::size_t>(it - local_in->begin())
                                                 : local_in->size();
  };
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k].local = position(paired_ids[k]);
  for (std::size_t k = 0; k < to_map.observations.size(); ++k) {
    const std::size_t i = ids[k] >= 0 ? position(ids[k]) : local_in->size();
    if (i == local_in->size()) continue;  // not mapped (cannot be triangulated)
    pairs.push_back({i, mapped_for[k]});
    mapped_points_.push_back({frame.t_us, ids[k], to_map.observations[k].z});
    ++e->mapped;
    ++stats_.landmarks_mapped;
  }
  return pairs;
}

bool DcCooperation::fuseConfirmed(const SharedLandmarks& m, const std::vector<ConfirmedPair>& pairs,
                                  const std::vector<StateLandmark>& local, bool answers_request,
                                  bool independent, VisualInertialSlam& slam, int64_t now_us,
                                  CoopOutbox* out, CoopEvent* e) {
  const int j = m.header.agent_id;
  const auto n = static_cast<Eigen::Index>(pairs.size());
  // The peer's estimates and their joint covariance R: the sender's own when the message has it
  // (the confirmed landmarks' blocks of it), else a bound. With marginals P_i only, for ANY
  // joint covariance with those diagonal blocks Σ ≤ blockdiag(m·P_i) (covariance intersection
  // of the m blocks with equal weights 1/m), so blockdiag(m·P_i) is consistent whatever the
  // correlations between the peer's landmarks (they share its vehicle error).
  const bool joint = m.joint_covariance.rows() == 3 * static_cast<Eigen::Index>(m.landmarks.size());
  CiPeerEstimates peer;
  peer.y.resize(3 * n);
  peer.R = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  peer.vehicle_trace = m.vehicle_cov_trace;
  Eigen::VectorXd d(3 * n);
  std::vector<VariableKey> keys;
  for (Eigen::Index k = 0; k < n; ++k) {
    const ConfirmedPair& pr = pairs[static_cast<std::size_t>(k)];
    const StateLandmark& l = local[pr.local];
    peer.ids.push_back(l.id);
    keys.push_back(VariableKey::landmark(static_cast<uint64_t>(l.id)));
    peer.y.segment<3>(3 * k) = pr.peer->p_LinN;
    d.segment<3>(3 * k) = pr.peer->p_LinN - l.p_LinN;
    if (!joint) peer.R.block<3, 3>(3 * k, 3 * k) = static_cast<double>(n) * pr.peer->covariance;
    for (Eigen::Index c = 0; joint && c < n; ++c) {
      const auto row = 3 * (pr.peer - m.landmarks.data());
      const auto col = 3 * (pairs[static_cast<std::size_t>(c)].peer - m.landmarks.data());
      peer.R.block<3, 3>(3 * k, 3 * c) = m.joint_covariance.block<3, 3>(row, col);
    }
  }
  // The set jointly, against the own joint covariance P1 of the landmarks: the NIS with bounds
  // on every unknown covariance is at most χ²(3m)-distributed for a consistent peer.
  Expected<Eigen::MatrixXd> P1 = CovarianceHelper::marginalCovariance(slam.state(), keys);
  if (!P1.ok()) {
    ++stats_.fusion_failures;
    return false;
  }
  e->independent = independent;
  e->nis_dof = static_cast<int>(3 * n);
  e->nis = independent ? d.dot((P1.value() + peer.R).ldlt().solve(d))
                       : ciBoundedNis(d, P1.value(), peer.R);
  e->r_scale = peers_[j].consistency.add(e->nis, e->nis_dof);
  // both_ways: return the local (pre-fusion) estimates of the confirmed landmarks, with the
  // pre-fusion provenance.
  if (o_.both_ways && answers_request) {
    std::vector<Correspondence> own;
    for (const ConfirmedPair& pr : pairs)
      own.push_back({static_cast<std::size_t>(pr.peer - m.landmarks.data()), &local[pr.local],
                     pr.peer->index});
    returnOwnEstimates(j, own, &P1.value(), slam, now_us, out);
  }
  if (e->nis > chiSquareQuantile(o_.gate_probability, e->nis_dof)) {
    ++stats_.rejected_joint_gate;
    e->rejected_gate += static_cast<int>(n);
    return true;
  }
  if (e->r_scale > 1.0) {
    peer.R *= e->r_scale;
    ++stats_.peer_down_weighted;
  }
  const Expected<CiChoice> ci =
      slam.ciUpdater().choose(slam.state(), peer, {o_.ci_method, o_.min_omega, independent});
  if (!ci.ok()) {
    ++stats_.fusion_failures;
    return false;
  }
  e->omega1 = ci->omega1;
  // When the peer's landmarks would not shrink the bound on the vehicle position, the CI update
  // only inflates the local state (an independent update always shrinks it). Not fusing is
  // always consistent.
  if (o_.require_vehicle_gain && !ci->vehicle_gain) {
    ++stats_.skipped_no_gain;
    e->no_gain = true;
    return true;
  }
  const Status fused = independent
                           ? slam.fuseIndependent(peer.ids, peer.y, peer.R)
                           : slam.fuseCovarianceIntersection(peer.ids, peer.y, peer.R, ci->omega1);
  if (fused.ok() && independent) ++stats_.fused_independent;
  if (!fused.ok()) {
    ++stats_.fusion_failures;
    return false;
  }
  // The state now holds the peer's information and everything its estimates held.
  std::vector<int> from = m.informed_by;
  if (from.empty()) from.push_back(j);
  std::vector<int> merged;
  std::set_union(informed_by_.begin(), informed_by_.end(), from.begin(), from.end(),
                 std::back_inserter(merged));
  informed_by_ = std::move(merged);
  for (const ConfirmedPair& pr : pairs)
    fused_matches_.push_back({now_us, j, local[pr.local].id, m.header.seq,
                              static_cast<int>(pr.peer - m.landmarks.data())});
  e->fused = static_cast<int>(n);
  stats_.landmarks_fused += n;
  ++stats_.exchanges_completed;
  return true;
}

void DcCooperation::forgetSilentPeers(int64_t now) {
  // Step 2: forget silent peers; abandon unanswered requests.
  for (auto it = peers_.begin(); it != peers_.end();) {
    if (seconds(now - it->second.last_heard_us) > o_.peer_timeout_s) {
      ++stats_.peer_timeouts;
      events_.push_back({now, CoopEventKind::kPeerLost, it->first, 0, 0, 0, 0, 1.0});
      it = peers_.erase(it);
      continue;
    }
    PeerState& p = it->second;
    if (p.request_pending && seconds(now - p.request_sent_us) > p.timeout.seconds()) {
      p.request_pending = false;
      p.timeout.onTimeout();
      ++stats_.request_timeouts;
      events_.push_back({now, CoopEventKind::kRequestTimeout, it->first,
                         static_cast<int>(p.requested.size()), 0, 0, 0, 1.0});
    }
    ++it;
  }
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

Status DcCooperation::afterFrame(const StereoFrameObservations& frame, VisualInertialSlam& slam,
                                 CoopOutbox* out) {
  if (out == nullptr) return Status::Error("DcCooperation::afterFrame: null outbox");
  out->clear();
  const int64_t now = frame.t_us;
  // 1. Messages of earlier epochs, in arrival order; later ones wait.
  std::deque<Inbound> later;
  while (!inbox_.empty()) {
    Inbound msg = std::move(inbox_.front());
    inbox_.pop_front();
    const int64_t t = std::visit([](const auto& m) { return m.header.t_us; }, msg);
    if (t >= now) {
      later.push_back(std::move(msg));
      continue;
    }
    if (auto* s = std::get_if<CoopSummary>(&msg))
      handleSummary(*s, now);
    else if (auto* i = std::get_if<FeatureIndexList>(&msg))
      handleIndex(*i, slam, frame, out);
    else if (auto* r = std::get_if<SharedRequest>(&msg))
      handleRequest(*r, slam, now, out);
    else if (auto* l = std::get_if<SharedLandmarks>(&msg))
      handleShared(*l, slam, frame, out);
  }
  inbox_.swap(later);

  forgetSilentPeers(now);
  stats_.peers_known = static_cast<int>(peers_.size());

  // 3. This frame's ellipsoid (§6.6.2) from the in-state landmarks observed now.
  const std::vector<StateLandmark> now_seen = observedNow(slam.stateLandmarks(), now);
  std::vector<Eigen::Vector3d> points;
  for (const StateLandmark& l : now_seen) points.push_back(l.p_LinN);
  const FeatureEllipsoid mine = ellipsoidOf(points);
  const int n_self = mine.count;
  const double own_vehicle_trace = vehiclePositionTrace(slam);

  if (last_summary_us_ < 0 || seconds(now - last_summary_us_) >= o_.summary_period_s) {
    CoopSummary s;
    s.header = nextHeader(kSummaryStream, now);
    s.boot_id = boot_id_;
    s.mean = mine.mean;
    s.std = mine.std;
    s.num_features = n_self;
    s.vehicle_cov_trace = own_vehicle_trace;
    out->summary = s;
    last_summary_us_ = now;
    ++stats_.summaries_sent;
  }

  // 4. Index broadcast when, for some cooperating peer, this agent observes fewer features;
  // and (offer_archived) the indices of the archived landmarks where a peer looks now.
  if (last_index_us_ >= 0 && seconds(now - last_index_us_) < o_.exchange_period_s)
    return Status::Ok();
  bool send = false, place = false;
  std::vector<int64_t> offer;
  for (const auto& [j, p] : peers_) {
    if (p.summary.header.agent_id != j) continue;  // no summary accepted yet
    if (seconds(now - p.summary.header.t_us) > o_.max_message_age_s) continue;
    FeatureEllipsoid theirs;
    theirs.mean = p.summary.mean;
    theirs.std = p.summary.std;
    theirs.count = p.summary.num_features;
    const std::optional<merge::FrameRelation> relation = relationOf(j);
    if (!relation) {
      place = placeDue(j, n_self, now) || place;
      continue;
    }
    if (!o_.frames_given) theirs = inOwnFrame(theirs, *relation);
    FeatureEllipsoid own = mine;
    if (o_.include_vehicle_uncertainty) {
      // Where the features are is uncertain by the vehicle position too (trace/3 per axis).
      own.std = (own.std.array().square() + own_vehicle_trace / 3.0).sqrt();
      theirs.std = (theirs.std.array().square() + p.summary.vehicle_cov_trace / 3.0).sqrt();
    }
    if (o_.offer_archived) archivedInView(slam, theirs, &offer);
    if (n_self == 0 || !ellipsoidsIntersect(own, theirs, o_.coop_sigma, o_.min_semi_axis_m))
      continue;
    const int n_peer = p.summary.num_features;
    if (n_self < n_peer || (n_self == n_peer && self_ < j)) send = true;
  }
  // Offers are answered for a while (the request comes back a frame or two later).
  for (auto it = offered_.begin(); it != offered_.end();)
    it = seconds(now - it->second) > o_.request_timeout_s ? offered_.erase(it) : std::next(it);
  if (!send && !place && offer.empty()) return Status::Ok();
  FeatureIndexList idx;
  idx.header = nextHeader(kIndexStream, now);
  idx.true_ids = o_.true_ids;
  if (send)
    for (const StateLandmark& l : now_seen) idx.indices.push_back(l.index);
  // The place descriptor is the local map: one frame's features are too few, and too close
  // together, to fix 4 dof.
  if (place)
    for (const StateLandmark& l : slam.stateLandmarks()) idx.indices.push_back(l.index);
  std::sort(offer.begin(), offer.end());
  offer.erase(std::unique(offer.begin(), offer.end()), offer.end());
  for (int64_t id : offer) {
    idx.indices.push_back(slam.archive().find(id)->index);
    offered_[id] = now;
  }
  std::sort(idx.indices.begin(), idx.indices.end());
  idx.indices.erase(std::unique(idx.indices.begin(), idx.indices.end()), idx.indices.end());
  if (static_cast<int>(idx.indices.size()) > o_.max_indices_per_message)
    idx.indices.resize(static_cast<std::size_t>(o_.max_indices_per_message));
  last_index_us_ = now;
  ++stats_.indices_sent;
  if (!offer.empty()) ++stats_.archive_offers;
  events_.push_back(
      {now, CoopEventKind::kIndexSent, 0, static_cast<int>(idx.indices.size()), 0, 0, 0, 1.0});
  out->index = std::move(idx);
  return Status::Ok();
}

void DcCooperation::recordSent(int64_t seq, std::vector<int64_t> ids) {
  sent_ids_[seq] = std::move(ids);
  if (sent_ids_.size() > kSentRecords) sent_ids_.erase(sent_ids_.begin());
}

int64_t DcCooperation::sentLandmarkId(int64_t seq, int slot) const {
  auto it = sent_ids_.find(seq);
  if (it == sent_ids_.end() || slot < 0 || slot >= static_cast<int>(it->second.size())) return -1;
  return it->second[static_cast<std::size_t>(slot)];
}

}  // namespace cvslam::coop
