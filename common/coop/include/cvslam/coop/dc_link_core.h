#pragma once
// The transport-independent core of one agent's DC link (docs/cooperation.md; thesis §6.6.5),
// shared by cvslam_run --mode dc (tools/dc_team_link.h: an in-process mailbox) and
// cvslam_agent --mode dc (transport dc_link.h: LCM). The adapters only move messages; this
// core does everything that must be the same in both paths:
//   - message ordering: peers' messages are held and handed to DcCooperation right before the
//     frame that may apply them (those older than the frame), in one canonical order — by
//     time, sender id, stream (summary, index, request, shared), sequence number — whatever
//     order they arrived in; a lockstep multi-process run then reproduces the in-process run;
//   - the cooperation log agent_<id>/coop.csv (coop_log.h);
//   - the statistics: bytes sent per stream and the one-line report of the counters.

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <variant>

#include "cvslam/coop/coop_messages.h"
#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/core/status.h"

namespace cvslam::coop {

/// A peer's message as DcCooperation takes it; the alternatives' order is the stream rank of
/// the canonical order.
using CoopMessage = std::variant<CoopSummary, FeatureIndexList, SharedRequest, SharedLandmarks>;

class DcLinkCore {
 public:
  DcLinkCore(int self_id, const DcCooperationOptions& options, int64_t boot_id);

  /// Opens run_dir/agent_<id>/coop.csv (creating the folder), and relations.csv when the frames
  /// are estimated. Without it no log is written.
  Status openLog(const std::string& run_dir);

  /// A message received from a peer, in any order (our own broadcasts are ignored).
  void receive(CoopMessage message);

  /// Right after the agent's frame: hands the held messages older than the frame to the
  /// cooperation in canonical order, runs its step on `slam` with the frame's observations
  /// (AgentFrame::observations; an empty frame at the frame time when there are none), logs its
  /// events; `out` gets the frame's outgoing messages.
  Status afterFrame(const StereoFrameObservations& frame, VisualInertialSlam& slam,
                    CoopOutbox* out);

  /// Counts `bytes` (encoded size) sent on `stream` (SUMMARY, INDEX, SHARED_REQ, SHARED).
  void countSent(const std::string& stream, int64_t bytes) { bytes_sent_[stream] += bytes; }

  /// One line: "UAV<id> (<ci> CI) cooperation: peers …, exchanges …, landmarks fused …;
  /// rejected: invalid …; … timeouts …[; <B/s> B/s (<stream> <B/s> …)]" with the byte rates over
  /// `duration_s` when bytes were counted.
  std::string report(double duration_s) const;

  int id() const { return dc_.selfId(); }
  const DcCooperation& cooperation() const { return dc_; }
  /// Messages DcCooperation refused when they were handed over (invalid, not for us).
  int64_t refused() const { return refused_; }

 private:
  Status openRelationsLog();
  /// (t_us, sender, stream rank = variant index, seq, arrival order)
  using Key = std::tuple<int64_t, int, std::size_t, int64_t, uint64_t>;

  DcCooperation dc_;
  std::ofstream log_;
  /// Estimated frames: opened with coop.csv; with the frames given, at the first verification
  /// (a peer that estimates in a frame of its own).
  std::ofstream relations_log_;
  std::string log_dir_;  ///< agent_<id>/ once openLog() ran
  std::map<Key, CoopMessage> pending_;
  uint64_t arrivals_ = 0;
  int64_t refused_ = 0;
  std::map<std::string, int64_t> bytes_sent_;
};

}  // namespace cvslam::coop
