#pragma once
// cvslam_run --mode cc: the in-process ground station of centralised cooperation (CC-VSLAM,
// coop/cc_team_filter.h). Every agent runs its own filter as in single mode (the fallback of
// the process version); after each frame its CcObservationBatch (coop/cc_batch_builder.h: the
// IMU samples since its previous batch and the frame's observations) goes to the joint filter at
// once, so batches are processed in (time, agent id) order, deterministically, and the agent
// records the ground station's estimate of its vehicle for that frame (always fresh in
// process). Each batch goes through the LCM encoding (transport/cc_convert.h: encode → decode
// → validate), as between cvslam_agent and the ground-station process, its bytes counted.
// Writes DIR/ground_station/ (coop/ground_station_recorder.h).

#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "cvslam/coop/cc_batch_builder.h"
#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/coop/ground_station_recorder.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/simrun/simulated_team_run.h"
#include "cvslam/slam/agent_run_recorder.h"

namespace cvslam {

class CcTeamLink {
 public:
  explicit CcTeamLink(const coop::CcTeamFilterOptions& options);

  /// Adds every agent of `run` to the joint filter at its filter's start (camera, x0, P0, IMU
  /// noise: SimulatedTeamRun::setup) and opens DIR/ground_station/.
  Status open(const std::string& run_dir, const RunInfo& info, const SimulatedTeamRun& run);

  /// Every IMU sample of agent `id` (as its filter got it).
  void addImu(int id, const ImuSample& sample);
  /// After agent `id`'s frame: its batch through the joint filter, the step recorded; the
  /// agent's record gets the ground station's estimate of the frame (`truth` may be null).
  Status afterFrame(int id, const AgentPipeline& agent, const Vector9d* truth,
                    AgentRunRecorder* recorder);

  /// images (local_ids): every cross-UAV association the ground station made.
  const std::vector<coop::CcCrossAssociation>& crossAssociations() const { return cross_; }

  /// landmarks.csv of the joint map and stats.json.
  Status close(const coop::GroundStationRecorder::LandmarkTruth& truth);
  void printSummary(std::FILE* out, double duration_s) const;

 private:
  coop::CcTeamFilter filter_;
  coop::GroundStationRecorder recorder_;
  std::map<int, coop::CcBatchBuilder> builders_;
  /// Each UAV's start, given to the filter before its first batch.
  struct Start {
    int64_t t_us;
    Eigen::VectorXd x_v;
    Eigen::MatrixXd P_v;
    const InsPropagatorOptions* ins;
    const StereoCamera* camera;
  };
  std::map<int, Start> starts_;
  std::map<int, const InsPropagatorOptions*> ins_;  // each UAV's IMU noise, for restarts
  std::map<int, int64_t> bytes_sent_;
  std::map<int, long> dropped_;  // batches that did not survive the wire, per UAV
  long restarts_ = 0;            // vehicles started again after a propagation refusal
  long dropped(int id) const { return dropped_.count(id) > 0 ? dropped_.at(id) : 0; }
  std::vector<coop::CcCrossAssociation> cross_;
};

}  // namespace cvslam
