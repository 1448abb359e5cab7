#include "cvslam/coop/dc_cooperation.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "cvslam/filter/chi_square.h"
#include "cvslam/filter/covariance_helper.h"
#include "cvslam/slam/visual_inertial_slam.h"
#include "dc_cooperation_detail.h"

namespace cvslam::coop {

using detail::seconds;

namespace {
enum Stream : int { kSummaryStream = 0, kIndexStream = 1, kRequestStream = 2, kSharedStream = 3 };
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
  // A peer not yet merged: its INDEX is a place descriptor. Either side asks (one exchange at
  // a time per peer; with both_ways the other side verifies the return), and only for
  // landmarks it has mapped, the ones a verification can use.
  const bool merged = relationOf(m.header.agent_id).has_value();
  std::vector<uint32_t> sorted = m.indices;
  std::sort(sorted.begin(), sorted.end());
  if (!merged) {
    // A place descriptor (the peer's local map): ask for the landmarks of it that this agent
    // mapped, in its state or its archive (the peer may fly where this agent flew before) —
    // unless its places failed to verify lately (max_place_backoff_s).
    if (now_us < p.next_place_request_us) return;
    SharedRequest r;
    for (const StateLandmark& l : placeLandmarks(slam, sorted)) r.indices.push_back(l.index);
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
  // Not again within reask_period_s what this peer was asked for lately.
  const auto reask_us = static_cast<int64_t>(std::llround(o_.reask_period_s * 1e6));
  for (auto it = p.asked_us.begin(); it != p.asked_us.end();)
    it = now_us - it->second >= reask_us ? p.asked_us.erase(it) : std::next(it);
  SharedRequest r;
  for (const StateLandmark& l : cand) {
    if (static_cast<int>(r.indices.size()) >= o_.max_landmarks_per_message) break;
    if (p.asked_us.count(l.index) != 0) continue;
    r.indices.push_back(l.index);
  }
  if (r.indices.empty()) return;
  std::sort(r.indices.begin(), r.indices.end());
  r.indices.erase(std::unique(r.indices.begin(), r.indices.end()), r.indices.end());
  if (reask_us > 0)
    for (uint32_t index : r.indices) p.asked_us[index] = now_us;
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
  if (framesShared(j)) {
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
  std::vector<uint32_t> indices;
  for (const SharedLandmark& l : m.landmarks) indices.push_back(l.index);
  std::sort(indices.begin(), indices.end());
  const std::vector<StateLandmark> place = placeLandmarks(slam, indices);
  const std::vector<Correspondence> matched = correspondences(m, place);
  verifyRelation(m, matched, slam, now_us);
  if (!relation) {
    ++stats_.skipped_unmerged;
    // The peer's verification would use the same correspondences: too few, nothing to send.
    if (o_.both_ways && answers_request &&
        static_cast<int>(matched.size()) >= o_.aligner.min_inliers)
      returnOwnEstimates(j, matched, nullptr, slam, now_us, out);
    return;
  }
  const SharedLandmarks carried = inOwnFrame(m, *relation);
  const std::vector<ConfirmedPair> pairs = confirm(carried, slam, frame, false, &local, &e);
  if (!pairs.empty() &&
      !fuseConfirmed(carried, pairs, local, answers_request, false, slam, now_us, out, &e))
    return;
  events_.push_back(e);
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
    s.own_frame = !o_.frames_given;
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
    if (!framesShared(j)) theirs = inOwnFrame(theirs, *relation);
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
