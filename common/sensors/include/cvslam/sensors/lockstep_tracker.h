#pragma once
// Bookkeeping of cvslam_replay's lockstep mode (docs/architecture.md), kept free of LCM so it can be
// tested alone. The process feeds it what it publishes and the STATUS reports it receives.
//
// Epoch: the events of one camera instant of the team — every event after the previous
// epoch's frames up to and including all frames (stereo pair or features, any agent) at the
// same play time. A stream that ends without a frame closes a last epoch at its end.
// Acknowledgement: participant p has processed epoch k when its latest status_t on
// UAV<p>/STATUS has processed_utime ≥ required(p), where required(p) is the largest
// header.utime published on a UAV<p>/* channel up to epoch k, or, for a participant that
// is not a replayed agent (ground station, id 0), the largest utime published to anyone
// (play time + the largest agent offset, the same as dataset time for simulations).
// Discovery: participants are given (default: the replayed agents); each must announce
// itself with one status_t (any processed_utime, e.g. −1) before the first epoch goes out.
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <vector>
#include "cvslam/sensors/sensor_stream.h"

namespace cvslam {

class LockstepTracker {
 public:
  /// `participants`: ids that must acknowledge; `agents`: ids whose streams are replayed.
  LockstepTracker(const std::vector<int>& participants, const std::vector<int>& agents);
  /// True if publishing an event of this type and play time would start a new epoch while
  /// the current one ends in frames, i.e. the caller must closeEpoch() and wait first.
  bool startsNewEpoch(SensorEventType type, int64_t play_us) const;
  /// Records one published event.
  void published(int agent_id, SensorEventType type, int64_t t_us, int64_t play_us);
  /// Ends the current epoch: from now on ready() needs acknowledgements of it.
  void closeEpoch();
  /// A status report from participant `id` (others are ignored).
  void onStatus(int id, int64_t processed_utime);
  /// Every participant announced itself and acknowledged every closed epoch.
  bool ready() const;
  /// Participants ready() is waiting for (for error messages).
  std::vector<int> waitingFor() const;
  int64_t epochsClosed() const { return epochs_closed_; }

 private:
  static constexpr int64_t kNothing = std::numeric_limits<int64_t>::min();
  std::set<int> agents_;
  std::map<int, int64_t> required_;   ///< per participant, for the closed epochs
  std::map<int, int64_t> processed_;  ///< per participant: latest report (absent: none yet)
  std::map<int, int64_t> open_max_;   ///< per agent: largest utime in the open epoch
  int64_t open_max_all_ = kNothing;
  bool frames_in_epoch_ = false;
  int64_t frame_play_us_ = 0;
  int64_t epochs_closed_ = 0;
};

}  // namespace cvslam
