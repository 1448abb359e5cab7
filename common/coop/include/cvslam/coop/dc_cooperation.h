#pragma once
// Decentralised cooperative VSLAM (DC-VSLAM, thesis §6.6.5; docs/conventions.md): one DcCooperation
// per agent runs the exchange protocol with every peer it hears, without transport. Per peer j:
//   1. summaries (TEAM/SUMMARY) carry j's cooperation ellipsoid and feature count; a new
//      boot_id means j restarted (its state here is reset); j is forgotten after
//      peer_timeout_s of dataset time without a message;
//   2. Coop(i, j) = the ellipsoids (mean ± coop_sigma·std of the landmarks observed now)
//      intersect (feature_ellipsoid.h); the agent observing FEWER features (tie: lower id)
//      broadcasts its feature indices (UAV<i>/INDEX) at most every exchange_period_s. With
//      offer_archived the INDEX also carries the indices of i's archived landmarks inside j's
//      ellipsoid (where j looks now): j may fly where i flew before (not in the thesis);
//   3. the receiver looks the indices up among its in-state landmarks and (map_shared_landmarks)
//      the points it observes now but has not mapped, and asks for the candidates it has not
//      asked j for within reask_period_s (SharedRequest on UAV<j>/SHARED_REQ);
//   4. the sender answers with positions, covariances, descriptors and its vehicle-covariance
//      trace (SharedLandmarks on UAV<i>/SHARED), from its state and the archived landmarks it
//      offered (the joint covariance only when all are in its state);
//   5. the receiver confirms each by descriptor distance (when both have descriptors) and a
//      χ² gate on the two estimates; a shared landmark with no in-state candidate may match an
//      unmapped observed point of the same index (descriptor check, χ² gate on where stereo
//      puts it), which is then mapped, as step 5 of the filter maps new points. It tests the
//      confirmed set jointly (a χ²(3m) gate and the
//      peer's innovation test over time, peer_consistency.h), then fuses it as ONE filter
//      update (slam/ci_updater.h): the EKF update when the provenance lists of the two
//      estimates are disjoint (they share no information, so they are independent),
//      covariance intersection otherwise (ω1 from the covariances fused); with both_ways it
//      also returns its own (pre-fusion) estimates of the confirmed landmarks, which the
//      sender fuses.
// Provenance: each agent keeps the set of agents whose information its state holds (itself,
// and the lists of everything it fused); SharedLandmarks carry it. Every gate uses a
// covariance that bounds the true one: P_own + P_peer for independent estimates, the CI bound
// (filter/covariance_intersection.h ciBoundedNis) otherwise, and for the peer's landmarks
// jointly blockdiag(m·P_i) (the message carries marginals only).
// Frames (docs/merge.md): with frames_given the agent estimates in the team's frame (the
// thesis), and so does every peer whose summaries do not say own_frame. Otherwise — this
// agent or the peer in a frame of its own — the 4-dof relation of the peer's frame in the
// own is "not yet found" or adopted (merge/). Until it is
// adopted the peer's ellipsoid means nothing here: the INDEX of the features observed now is
// sent every place_period_s as a place descriptor (true ids stand in for appearance at the
// feature level; after failed verifications the peer asks less often, max_place_backoff_s),
// and every SharedLandmarks from the peer is a geometric verification
// (FourDofAligner on the landmarks both hold, with both joint covariances), a candidate for
// the FrameRelationBook, never fused. Once adopted, a peer's ellipsoid and landmarks are
// carried into the own frame with the relation's uncertainty added, fused by covariance
// intersection (the relation was made from the own map, so they are not independent of it),
// and every exchange also verifies the relation again (a gated refinement). A restarted peer
// loses its relation.
// Inbound messages are validated when they arrive and queued; afterFrame applies those older
// than the frame (epoch semantics, docs/cooperation.md). Stale, duplicated and reordered
// messages are dropped and counted. Everything is deterministic in the message order.

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "cvslam/camera/stereo_observation.h"
#include "cvslam/coop/coop_messages.h"
#include "cvslam/coop/feature_ellipsoid.h"
#include "cvslam/coop/peer_consistency.h"
#include "cvslam/coop/request_timeout.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/covariance_intersection.h"
#include "cvslam/merge/four_dof_aligner.h"
#include "cvslam/merge/frame_relation_book.h"

namespace cvslam {
class ConfigNode;
class VisualInertialSlam;
struct StateLandmark;
}  // namespace cvslam

namespace cvslam::coop {

// The CI weighting the options name (filter/covariance_intersection.h), under the protocol's
// namespace as the tools spell it.
using cvslam::CiMethod;
using cvslam::ciMethodName;
using cvslam::parseCiMethod;

/// Config section `coop:` of agent.yaml.
struct DcCooperationOptions {
  double coop_sigma = 2.0;  ///< ellipsoid semi-axes = coop_sigma · std (§6.6.2)
  /// Floor of the semi-axes (one feature, planar sets) [m].
  double min_semi_axis_m = 1.0;
  /// Widen both ellipsoids by the agents' vehicle position variance (trace/3 per axis):
  /// the features' estimated positions are off by the vehicle error. false: the thesis's
  /// ellipsoid of the feature spread only.
  bool include_vehicle_uncertainty = true;
  double summary_period_s = 0.5;   ///< summary/heartbeat period [s]
  double exchange_period_s = 0.0;  ///< at most one index broadcast per period [s]; 0: every frame
  /// A landmark is asked of the same peer at most once per this period [s]; 0: whenever it is
  /// in the peer's index (the thesis, §6.6.5). Most answers to a repeated request fuse nothing
  /// (the estimates on both sides barely moved since), and they were most of the traffic
  /// (docs/cooperation.md "Traffic").
  double reask_period_s = 1.0;
  double peer_timeout_s = 5.0;  ///< a silent peer is forgotten after this [s]
  /// An unanswered request is abandoned (and the next index asks again) after a timeout that
  /// follows the measured round trip (request_timeout.h), between these bounds [s]: the
  /// first request waits min_request_timeout_s; back-off stops at request_timeout_s.
  double min_request_timeout_s = 0.5;
  double request_timeout_s = 2.0;
  double max_message_age_s = 2.0;  ///< older messages (dataset time) are dropped as stale [s]
  CiMethod ci_method = CiMethod::kAdaptive;  ///< adaptive | fast | optimal_trace |
                                             ///< optimal_determinant | optimal_vehicle
  bool both_ways = true;  ///< the receiver also returns its estimates to the sender
  int max_landmarks_per_message =
      50;  ///< landmarks per request / SharedLandmarks (sent and accepted)
  int max_indices_per_message = 2000;  ///< indices per FeatureIndexList (sent and accepted)
  double gate_probability = 0.999;     ///< χ²(3) gate on p_own − p_peer with P_own + P_peer
  /// Descriptor distance (L2 over the bytes) above which a shared candidate is rejected;
  /// only used when both estimates carry a descriptor of the same length.
  double max_descriptor_distance = 250.0;
  double max_position_m = 1.0e5;            ///< |p| above this is absurd [m]
  double max_landmark_variance_m2 = 1.0e4;  ///< covariance eigenvalues above this are absurd [m²]
  double min_landmark_variance_m2 = 1.0e-12;  ///< ... below this (not PD) too [m²]
  /// Smallest weight of the own estimate: ω1 → 0 would scale the local prior by 1/ω1 → ∞.
  double min_omega = 0.05;
  /// Fuse only when the CI update shrinks the trace of the vehicle position covariance
  /// (otherwise it only inflates the local state; not fusing is always consistent).
  bool require_vehicle_gain = true;
  /// Fuse estimates whose provenance is disjoint from the own state's with the EKF update (they
  /// are independent); false: always covariance intersection (the thesis).
  bool use_provenance = true;
  /// The innovation test over time of each peer (YAML consistency_window,
  /// consistency_probability).
  PeerConsistencyOptions consistency;
  int max_queued_messages = 1000;
  /// Peers tracked at most; summaries of further agents are dropped (rejected_too_many_peers),
  /// so that a flood of forged agent ids cannot grow the state without bound.
  int max_peers = 64;
  /// The receiver also matches a peer's landmarks to the points it observes now but has not
  /// mapped (same index, descriptor check, χ² gate on where stereo puts them), maps those and
  /// fuses the peer's estimates into them: two UAVs rarely map the same surface points, so with
  /// images an exchange between in-state landmarks alone finds few (docs/cooperation.md
  /// "Cooperation where the views do not overlap at the same time"). false: in-state landmarks
  /// only (the thesis).
  bool map_shared_landmarks = true;
  /// Also broadcast the indices of the own archived landmarks inside a peer's cooperation
  /// ellipsoid (where it looks now), and answer its requests from them: a UAV that flies where
  /// another flew before gains from that UAV's map, as the ground station's shared map does
  /// (docs/cooperation.md, the same section). false: the thesis (live overlaps only).
  bool offer_archived = true;
  int max_offered_landmarks = 30;  ///< archived landmarks offered per INDEX, nearest first
  /// Indices are true landmark ids (feature-level simulation); set by the runner, not YAML.
  bool true_ids = false;
  /// This agent starts in the team's frame (a known start); false: in a frame of its own, the
  /// frames to its peers estimated (see above). Set by the runner from the start, not YAML.
  bool frames_given = true;
  /// Section `merge:` — estimated frames only: the place descriptor's period towards a peer
  /// not yet merged [s] (YAML place_period_s), the geometric verification (`aligner:`) and
  /// the adoption rule (`relations:`).
  double place_period_s = 1.0;
  /// After consecutive failed verifications of a peer not yet merged, its places are asked
  /// for less often: the wait doubles from place_period_s up to this [s] (YAML
  /// max_place_backoff_s), and a verified candidate resets it. A peer that never overlaps —
  /// or whose places this agent cannot match — then costs little.
  double max_place_backoff_s = 8.0;
  merge::FourDofAlignerOptions aligner;
  merge::FrameRelationBookOptions relations;
  Status load(const ConfigNode& node);
};

struct DcCooperationStatistics {
  int64_t summaries_sent = 0, summaries_received = 0;
  int64_t indices_sent = 0, indices_received = 0;
  int64_t requests_sent = 0, requests_received = 0;
  int64_t shared_sent = 0, shared_received = 0;
  int64_t exchanges_completed = 0;  ///< SharedLandmarks fused (≥ 1 landmark)
  int64_t landmarks_fused = 0;
  int64_t rejected_invalid = 0;     ///< failed validation (non-finite, absurd, too large)
  int64_t rejected_not_for_me = 0;  ///< directed to another agent, or from self
  int64_t rejected_stale = 0;
  int64_t rejected_duplicate = 0;
  int64_t rejected_reordered = 0;
  int64_t rejected_queue_full = 0;
  int64_t rejected_too_many_peers = 0;
  int64_t rejected_unknown_peer = 0;  ///< index/request/shared from a peer with no summary yet
  int64_t rejected_gate = 0;          ///< shared landmarks failing the χ² gate
  int64_t rejected_descriptor = 0;    ///< shared landmarks failing the descriptor check
  int64_t shared_not_in_state = 0;    ///< shared landmarks neither in the state nor observed now
  int64_t landmarks_mapped = 0;       ///< observed points mapped for a peer's landmark
  int64_t archive_offers = 0;         ///< INDEX messages offering archived landmarks
  int64_t fusion_failures = 0;        ///< CI updates the filter refused
  int64_t skipped_no_gain = 0;        ///< confirmed sets not fused (require_vehicle_gain)
  int64_t fused_independent = 0;      ///< exchanges fused by the EKF update (provenance)
  int64_t rejected_joint_gate = 0;    ///< confirmed sets failing the joint χ²(3m) gate
  int64_t peer_down_weighted = 0;     ///< exchanges whose R was scaled (peer_consistency.h)
  int64_t request_timeouts = 0;
  int64_t peer_restarts = 0;
  int64_t peer_timeouts = 0;
  int64_t verifications = 0;         ///< SharedLandmarks from a peer verified geometrically
  int64_t verifications_failed = 0;  ///< ... that gave no relation (too few inliers, ...)
  int64_t relations_adopted = 0;
  int64_t relations_refined = 0;
  int64_t relations_rejected = 0;  ///< verified candidates the book refused
  int64_t skipped_unmerged = 0;    ///< SharedLandmarks not fused: no relation yet
  int peers_known = 0;
};

/// One geometric verification of a peer's frame and what the book decided
/// (agent_<id>/relations.csv).
struct RelationRecord {
  int64_t t_us = 0;
  int peer = 0;
  std::string verdict;  ///< failed | pending | adopted | refined | rejected
  std::string reason;   ///< one line
  int correspondences = 0, inliers = 0;
  double nis = 0.0;                ///< against the adopted relation (refined, rejected)
  merge::FrameRelation candidate;  ///< the verified relation (peer's frame → own), if any
};

/// The frame this agent reports its trajectory in for the team (docs/merge.md): the team's
/// given frame when itself or a peer it merged with estimates in it (named by the lowest such
/// id), else the own frame of the lowest id among itself and the peers it adopted.
struct TeamFrame {
  int root = 0;                      ///< whose frame
  merge::FrameRelation own_in_root;  ///< own frame → root's (identity when root is self)
  bool merged = false;               ///< some peer's relation is adopted

  /// A vehicle state [p_BinN, v_B, φ θ ψ] of the own frame in the root's (the body velocity
  /// and roll, pitch are the same in both gravity-aligned frames).
  Eigen::Matrix<double, 9, 1> apply(const Eigen::Matrix<double, 9, 1>& x_own) const;
};

enum class CoopEventKind {
  kPeerJoined,
  kPeerRestarted,
  kPeerLost,
  kIndexSent,
  kRequestSent,
  kSharedSent,
  kFused,
  kRequestTimeout,
};
std::string coopEventName(CoopEventKind kind);

/// One cooperation event for events/coop.csv.
struct CoopEvent {
  int64_t t_us = 0;  ///< frame time at which it happened [µs]
  CoopEventKind kind = CoopEventKind::kFused;
  int peer = 0;
  int count = 0;                ///< indices / requested / sent / received landmarks
  int fused = 0;                ///< kFused: landmarks fused
  int rejected_gate = 0;        ///< kFused
  int rejected_descriptor = 0;  ///< kFused
  double omega1 = 1.0;          ///< kFused: weight of the own estimate
  int not_in_state = 0;         ///< kFused: landmarks neither in the state nor observed now
  int mapped = 0;               ///< kFused: observed points mapped for the peer's landmarks
  bool no_gain = false;         ///< kFused: not fused (require_vehicle_gain)
  bool independent = false;     ///< kFused: by the EKF update (disjoint provenance)
  double nis = 0.0;             ///< kFused: joint NIS of the confirmed set
  int nis_dof = 0;              ///< kFused: its degrees of freedom (3 per landmark)
  double r_scale = 1.0;         ///< kFused: scale of the peer's R (peer_consistency.h)
};

/// A landmark pair this agent fused with a peer's estimate: which of the own landmarks, and
/// which entry of which of the peer's SharedLandmarks. For an in-process audit of the matches
/// against a simulator's truth (simrun/cross_uav_match_audit.h); nothing of it is sent.
struct FusedMatch {
  int64_t t_us = 0;       ///< frame time of the fusion [µs]
  int peer = 0;           ///< the sender
  int64_t local_id = -1;  ///< the own landmark
  int64_t peer_seq = 0;   ///< header.seq of the sender's SharedLandmarks
  int slot = 0;           ///< position of the peer's landmark in that message
};

/// A point of the own frame this agent mapped for a peer's landmark (map_shared_landmarks):
/// the new landmark and where it was observed, for an in-process audit against a simulator's
/// truth (the renderer's surface at that pixel); nothing of it is sent.
struct MappedPoint {
  int64_t t_us = 0;                             ///< frame time [µs]
  int64_t local_id = -1;                        ///< the new landmark
  Eigen::Vector4d z = Eigen::Vector4d::Zero();  ///< its observation [u_L v_L u_R v_R] [px]
};

class DcCooperation {
 public:
  DcCooperation(int self_id, const DcCooperationOptions& options, int64_t boot_id);

  // Inbound: validated (finite, sane sizes and magnitudes, not from self), then QUEUED; nothing
  // is applied until afterFrame. Return false (and count) when rejected.
  bool onSummary(const CoopSummary& message);
  bool onIndex(const FeatureIndexList& message);
  bool onRequest(const SharedRequest& message);   ///< ignored unless to_agent == self
  bool onShared(const SharedLandmarks& message);  ///< ignored unless to_agent == self

  /// Called right after slam.processFrame(frame). Handles the queued inbound messages with
  /// header.t_us < frame.t_us, forgets timed-out peers, answers requests, fuses received
  /// shared landmarks into `slam`, then emits this frame's messages into *out (cleared first).
  Status afterFrame(const StereoFrameObservations& frame, VisualInertialSlam& slam,
                    CoopOutbox* out);

  const DcCooperationStatistics& statistics() const { return stats_; }
  std::vector<CoopEvent> takeEvents();
  std::vector<int> peers() const;  ///< currently known (not timed out), ascending
  int selfId() const { return self_; }
  /// Every landmark pair fused so far, in order.
  const std::vector<FusedMatch>& fusedMatches() const { return fused_matches_; }
  /// Every point mapped for a peer's landmark so far, in order.
  const std::vector<MappedPoint>& mappedPoints() const { return mapped_points_; }
  /// The own landmark id in entry `slot` of the SharedLandmarks this agent sent with header
  /// seq `seq` (one of the last kSentRecords), or -1.
  int64_t sentLandmarkId(int64_t seq, int slot) const;
  const DcCooperationOptions& options() const { return o_; }
  /// The adopted relation of `peer`'s frame in the own (frames_given: identity, exact), or
  /// nullopt while it is not yet found.
  std::optional<merge::FrameRelation> relationOf(int peer) const;
  /// Whether this agent and `peer` estimate in the team's given frame (frames_given, and the
  /// peer's summaries do not say own_frame): then nothing needs finding between them. A peer
  /// in a frame of its own is merged by place exchanges, whatever this agent's start.
  bool framesShared(int peer) const;
  TeamFrame teamFrame() const;
  /// The own state `x_own` in the team frame and that frame's root, when the agent estimates
  /// in a frame of its own and has merged (trajectory_team.tum); false otherwise (frames
  /// given: the own frame is the team's; not merged: no team frame yet).
  bool teamState(const Eigen::Matrix<double, 9, 1>& x_own, int* root,
                 Eigen::Matrix<double, 9, 1>* x_team) const;
  std::vector<RelationRecord> takeRelationRecords();

 private:
  struct PeerState {
    int64_t boot_id = 0;
    CoopSummary summary;              ///< latest
    int64_t last_heard_us = 0;        ///< header time of the latest accepted message
    std::map<int, int64_t> last_seq;  ///< stream -> highest accepted seq
    bool request_pending = false;
    int64_t request_sent_us = 0;
    std::vector<uint32_t> requested;       ///< indices of the pending request (ascending)
    std::map<uint32_t, int64_t> asked_us;  ///< index -> when it was last asked (reask_period_s)
    int place_failures = 0;                ///< consecutive failed verifications, not merged
    int64_t next_place_request_us = 0;     ///< no place request before (max_place_backoff_s)
    RequestTimeout timeout;                ///< how long to wait for its answer
    PeerConsistency consistency;           ///< its innovation test over time
  };
  using Inbound = std::variant<CoopSummary, FeatureIndexList, SharedRequest, SharedLandmarks>;

  bool enqueue(Inbound message);
  /// Stale / duplicate / reordered / unknown-peer checks; updates last_seq and last_heard.
  bool admit(int stream, const CoopHeader& header, int64_t now_us);
  void handleSummary(const CoopSummary& m, int64_t now_us);
  void handleIndex(const FeatureIndexList& m, const VisualInertialSlam& slam,
                   const StereoFrameObservations& frame, CoopOutbox* out);
  void handleRequest(const SharedRequest& m, const VisualInertialSlam& slam, int64_t now_us,
                     CoopOutbox* out);
  void handleShared(const SharedLandmarks& m, VisualInertialSlam& slam,
                    const StereoFrameObservations& frame, CoopOutbox* out);
  /// A peer's landmark (entry `peer` of its message, index `index`) and the own in-state
  /// landmark of the same index (and an agreeing descriptor).
  struct Correspondence {
    std::size_t peer;
    const StateLandmark* own;
    uint32_t index;
  };
  std::vector<Correspondence> correspondences(const SharedLandmarks& m,
                                              const std::vector<StateLandmark>& local) const;
  /// Estimated frames: the matched landmarks (both joint covariances) verified geometrically,
  /// the relation a candidate for the book; recorded either way.
  void verifyRelation(const SharedLandmarks& m, const std::vector<Correspondence>& matched,
                      const VisualInertialSlam& slam, int64_t now_us);
  /// Forgets the peers silent for peer_timeout_s; abandons requests past their timeout.
  void forgetSilentPeers(int64_t now);
  /// Whether a place descriptor is due to the unmerged `peer` now (and notes it sent).
  bool placeDue(int peer, int n_self, int64_t now_us);
  /// The SharedRequest to `peer` (pending until answered).
  void sendRequest(int peer, SharedRequest r, int64_t now_us, CoopOutbox* out);
  /// The own landmarks with one of `indices` (ascending) that a place can be recognised by:
  /// the state's, then the archived ones (held ones as the state holds them now), by id.
  static std::vector<StateLandmark> placeLandmarks(const VisualInertialSlam& slam,
                                                   const std::vector<uint32_t>& indices);
  /// The joint covariance of the own landmarks of `own` when all are in the state (held ones
  /// included), else nullopt.
  static std::optional<Eigen::MatrixXd> exactJointCovariance(const std::vector<Correspondence>& own,
                                                             const VisualInertialSlam& slam);
  /// That, or a bound on it when some are archived with their marginals only.
  static Eigen::MatrixXd ownJointCovariance(const std::vector<Correspondence>& own,
                                            const VisualInertialSlam& slam);
  /// The peer's message carried into the own frame by `r` (covariances, joint included, with
  /// the relation's uncertainty added).
  static SharedLandmarks inOwnFrame(const SharedLandmarks& m, const merge::FrameRelation& r);
  /// The peer's ellipsoid carried into the own frame by `r`.
  static FeatureEllipsoid inOwnFrame(const FeatureEllipsoid& e, const merge::FrameRelation& r);
  /// both_ways: the own estimates of `own` returned to `peer` (with their joint covariance:
  /// `joint`, or from the state when null).
  void returnOwnEstimates(int peer, const std::vector<Correspondence>& own,
                          const Eigen::MatrixXd* joint, const VisualInertialSlam& slam,
                          int64_t now_us, CoopOutbox* out);
  /// A shared landmark confirmed against a local one (local: index into the local list).
  struct ConfirmedPair {
    std::size_t local;
    const SharedLandmark* peer;
  };
  /// Step 5: confirms the shared landmarks by descriptor distance and the χ² gate, counting
  /// the rejections in *e and the statistics. A shared landmark with no in-state candidate may
  /// be matched to an unmapped observation of `frame` instead (map_shared_landmarks): those
  /// are mapped here, and *local is read again.
  std::vector<ConfirmedPair> confirm(const SharedLandmarks& m, VisualInertialSlam& slam,
                                     const StereoFrameObservations& frame, bool independent,
                                     std::vector<StateLandmark>* local, CoopEvent* e);
  /// The unmapped observation of `frame` that best matches `s` (same index, descriptor check,
  /// pairNis within `gate`, confirm's χ²(3) gate, on its triangulated point), or -1; `taken`
  /// marks observations already matched.
  int matchUnmapped(const SharedLandmark& s, const VisualInertialSlam& slam,
                    const StereoFrameObservations& frame, bool independent, double gate,
                    const std::vector<bool>& taken) const;
  /// Appends the own archived landmarks inside `view` (a peer's ellipsoid) to *offer.
  void archivedInView(const VisualInertialSlam& slam, const FeatureEllipsoid& view,
                      std::vector<int64_t>* offer) const;
  /// The descriptor check: true when either has none or they differ in length.
  bool descriptorsAgree(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) const;
  /// The χ² statistic of two estimates of one landmark (P_a + P_b when independent, else the
  /// covariance-intersection bound).
  static double pairNis(const Eigen::Vector3d& d, const Eigen::Matrix3d& P_a,
                        const Eigen::Matrix3d& P_b, bool independent);
  /// Tests the confirmed landmarks jointly and fuses them (slam/ci_updater.h: the EKF update
  /// when `independent`, CI otherwise), returning the own estimates with both_ways; false when
  /// the filter refused (no event is recorded then).
  bool fuseConfirmed(const SharedLandmarks& m, const std::vector<ConfirmedPair>& pairs,
                     const std::vector<StateLandmark>& local, bool answers_request,
                     bool independent, VisualInertialSlam& slam, int64_t now_us, CoopOutbox* out,
                     CoopEvent* e);
  CoopHeader nextHeader(int stream, int64_t t_us);
  /// A received joint covariance is 3m × 3m, finite, symmetric, positive definite, and its
  /// diagonal blocks are the landmarks' covariances.
  bool validJointCovariance(const SharedLandmarks& m) const;
  /// Estimates with this provenance share no information with the own state.
  bool independentOf(const std::vector<int>& informed_by) const;

  int self_;
  DcCooperationOptions o_;
  int64_t boot_id_;
  std::deque<Inbound> inbox_;
  std::map<int, PeerState> peers_;
  std::map<int, int64_t> next_seq_;  ///< stream -> next seq to send
  int64_t last_summary_us_ = -1;
  int64_t last_index_us_ = -1;
  DcCooperationStatistics stats_;
  std::vector<CoopEvent> events_;
  std::vector<int> informed_by_;  ///< provenance of the own state, ascending
  std::vector<FusedMatch> fused_matches_;
  std::vector<MappedPoint> mapped_points_;
  std::map<int64_t, int64_t> offered_;  ///< archived landmark id -> time last offered [µs]
  static constexpr std::size_t kSentRecords = 256;
  std::map<int64_t, std::vector<int64_t>> sent_ids_;  ///< SHARED seq -> own landmark ids
  merge::FourDofAligner aligner_;
  merge::FrameRelationBook relations_;
  std::vector<RelationRecord> relation_records_;
  std::map<int, int64_t> last_place_us_;  ///< peer -> when the last place INDEX went to it
  /// Records the own landmark ids of an outgoing SharedLandmarks (its header.seq).
  void recordSent(int64_t seq, std::vector<int64_t> ids);
};

}  // namespace cvslam::coop
