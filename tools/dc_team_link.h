#pragma once
// cvslam_run --mode dc: the in-process adapter of the DC link (coop/dc_link_core.h). One
// DcLinkCore per simulated UAV, linked by a mailbox that carries the LCM-ENCODED messages
// (coop_convert.h: encode → decode → validate, exactly what cvslam_agent does over the
// network). Messages an agent emits after its frame at time t are handed to the peers' cores
// at once; each core applies them in its agent's first frame after t (epoch semantics,
// docs/cooperation.md), so the run is deterministic. The core writes agent_<id>/coop.csv;
// the bytes per stream also go to the agent's run writer (stats.json).

#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cvslam/coop/dc_link_core.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {

/// A lossy radio between the simulated UAVs (cvslam_run --coop-loss): each delivery of a
/// message to each receiver is lost independently with this probability. The draws follow
/// the deterministic delivery order, so one seed is one loss pattern.
struct DcLinkLoss {
  double percent = 0.0;
  uint64_t seed = 1;
};

class DcTeamLink {
 public:
  /// One agent per entry of `options_by_agent` (id → its options: frames_given is each
  /// agent's own, as its process would have it). Boot ids are fixed (1000 + id) so that runs
  /// repeat exactly.
  explicit DcTeamLink(const std::map<int, coop::DcCooperationOptions>& options_by_agent,
                      const DcLinkLoss& loss = {});

  /// Opens DIR/agent_<id>/coop.csv for every agent.
  Status open(const std::string& run_dir);

  /// After the frame of agent `id` (its observations): cooperation step, then encode and
  /// deliver its outbox (bytes counted in `writer` too).
  Status afterFrame(int id, const StereoFrameObservations& frame, VisualInertialSlam& slam,
                    AgentRunWriter* writer);

  /// Per-UAV cooperation report (dc_link_core.h), bytes per second over `duration_s`.
  void printSummary(std::FILE* out, double duration_s) const;

  const coop::DcCooperation& agent(int id) const { return agents_.at(id)->cooperation(); }

 private:
  std::map<int, std::unique_ptr<coop::DcLinkCore>> agents_;
  int64_t decode_failures_ = 0;
  DcLinkLoss loss_;
  std::mt19937_64 loss_rng_;
  int64_t deliveries_ = 0, lost_ = 0;
};

}  // namespace cvslam
