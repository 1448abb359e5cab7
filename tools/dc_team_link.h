#pragma once
// cvslam_run --mode dc: one DcCooperation per simulated UAV, linked by an in-process mailbox
// that carries the LCM-ENCODED messages (coop_convert.h: encode → decode → validate, exactly
// what cvslam_agent does over the network). Messages an agent emits after its frame at time t
// are handed to the peers at once; DcCooperation queues them and applies them in the peer's
// first frame after t (epoch semantics, docs/cooperation.md), so the run is deterministic.
// Records every cooperation event in agent_<id>/coop.csv and the bytes per stream in the
// agent's run writer (stats.json).

#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cvslam/coop/dc_cooperation.h"
#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/message_types.h"
#include "cvslam/simrun/simulated_team_run.h"

namespace cvslam {

class DcTeamLink {
 public:
  /// boot ids are fixed (1000 + id) so that runs repeat exactly.
  DcTeamLink(const coop::DcCooperationOptions& options, const std::vector<int>& agent_ids);

  /// Opens DIR/agent_<id>/coop.csv for every agent.
  Status open(const std::string& run_dir);

  /// After the frame of f.agent_id: cooperation step, then encode and deliver its outbox.
  Status afterFrame(const SimulatedFrame& f, AgentRunWriter* writer);

  /// Per-UAV cooperation counters and bytes per second over `duration_s`.
  void printSummary(std::FILE* out, double duration_s) const;

  const coop::DcCooperation& agent(int id) const { return *agents_.at(id); }

 private:
  /// Encodes `msg` (an lcmtype), counts its bytes for `stream`, decodes it again and hands
  /// the validated result to `deliver` for each addressee.
  template <typename Msg, typename Deliver>
  Status send(int from, const std::string& stream, Msg msg, AgentRunWriter* writer,
              const Deliver& deliver);

  /// Hands a decoded message from `from` to its addressee(s) (`to`: directed messages).
  void deliver(int from, int to, const cvslam::agent_summary_t& msg);
  void deliver(int from, int to, const cvslam::feature_index_t& msg);
  void deliver(int from, int to, const cvslam::shared_request_t& msg);
  void deliver(int from, int to, const cvslam::shared_landmarks_t& msg);

  std::map<int, std::unique_ptr<coop::DcCooperation>> agents_;
  std::map<int, std::ofstream> csv_;
  std::map<int, std::map<std::string, int64_t>> bytes_;
  int64_t decode_failures_ = 0;
};

}  // namespace cvslam
