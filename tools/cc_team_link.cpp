#include "cc_team_link.h"

#include <cmath>
#include <limits>
#include <vector>

#include "cvslam/io/run_writer.h"
#include "cvslam/lcm/cc_convert.h"
#include "cvslam/lcm/codec.h"

namespace cvslam {

CcTeamLink::CcTeamLink(const coop::CcTeamFilterOptions& options) : filter_(options) {}

Status CcTeamLink::open(const std::string& run_dir, const RunInfo& info,
                        const SimulatedTeamRun& run) {
  for (std::size_t i = 0; i < run.agentCount(); ++i) {
    const int id = run.agentId(i);
    const AgentFilterSetup& setup = run.setup(i);
    const VisualInertialSlam& slam = run.slam(i);
    // §6.3.1: the ground station knows every UAV's initial pose: the agent's own start, as
    // cvslam_agent sends it (transport/cc_link.h onStart). Added before the UAV's first batch,
    // as the ground-station process adds it when that POSE arrives (same state layout).
    starts_[id] = {slam.time(), slam.vehicleState(), slam.vehicleCovariance(), &setup.options.ins,
                   &slam.camera()};
    ins_[id] = &setup.options.ins;
    builders_.emplace(id, coop::CcBatchBuilder(id));
    filter_.setLinearisationOracle(id, run.truthOracle(i));  // null unless --linearise-at-truth
  }
  return recorder_.open(run_dir, info);
}

void CcTeamLink::addImu(int id, const ImuSample& sample) {
  auto it = builders_.find(id);
  if (it != builders_.end()) it->second.addImu(sample);
}

Status CcTeamLink::afterFrame(int id, const AgentPipeline& agent, const Vector9d* truth,
                              AgentRunRecorder* recorder) {
  auto it = builders_.find(id);
  if (it == builders_.end()) return Status::Error("cc: unknown agent " + std::to_string(id));
  const coop::CcObservationBatch sent = it->second.takeBatch(agent.lastFrame());
  // The batch as on the wire (transport/cc_convert.h: toMessage → encode → decode →
  // fromMessage, exactly what cvslam_agent and the ground-station process do): its bytes are
  // sent by the agent and received by the ground station; one that does not survive is dropped.
  Expected<cvslam::observation_batch_t> msg = transport::toMessage(sent);
  if (!msg.ok()) return msg.status();
  Expected<std::vector<uint8_t>> bytes = transport::encodeMessage(*msg);
  if (!bytes.ok()) return bytes.status();
  const auto n = static_cast<int64_t>(bytes->size());
  bytes_sent_[id] += n;
  recorder->writer().addBytesSent("OBS", n);
  recorder_.addBytesReceived("OBS", n);
  Expected<cvslam::observation_batch_t> back =
      transport::decodeMessage<cvslam::observation_batch_t>(bytes->data(), bytes->size());
  Expected<coop::CcObservationBatch> received =
      back.ok() ? transport::fromMessage(*back) : Expected<coop::CcObservationBatch>(back.status());
  if (!received.ok()) {
    recorder_.addDropped("decode", id, n);
    ++dropped_[id];
    return recorder->addFrame(agent, truth, std::numeric_limits<double>::quiet_NaN(), nullptr);
  }
  const coop::CcObservationBatch& batch = *received;
  if (auto start = starts_.find(id); start != starts_.end()) {
    const Start& s = start->second;
    if (Status st = filter_.addVehicle(id, *s.camera, s.t_us, s.x_v, s.P_v, s.ins); !st.ok())
      return st;
    starts_.erase(start);
  }
  coop::CcStepReport report;
  // A rejected batch is counted by the filter; the agent then records its own estimate.
  const Status step = filter_.processBatch(batch, &report);
  for (const coop::CcCrossAssociation& c : filter_.takeCrossAssociations()) cross_.push_back(c);
  if (Status s = recorder_.addStep(filter_, report, truth); !s.ok()) return s;
  if (!step.ok()) {
    // A vehicle whose IMU cannot reach the frame starts again from the agent's own estimate
    // at its next batch, as the ground-station process restarts it from the agent's POSE.
    if (report.refusal == coop::CcRefusal::kPropagation) {
      const VisualInertialSlam& slam = agent.slam();
      starts_[id] = {slam.time(), slam.vehicleState(), slam.vehicleCovariance(), ins_.at(id),
                     &slam.camera()};
      ++restarts_;
    }
    return recorder->addFrame(agent, truth, std::numeric_limits<double>::quiet_NaN(), nullptr);
  }
  Expected<VehicleEstimate> adopted = filter_.estimate(id);
  if (!adopted.ok()) return adopted.status();
  return recorder->addFrame(agent, truth, std::numeric_limits<double>::quiet_NaN(), &*adopted);
}

Status CcTeamLink::close(const coop::GroundStationRecorder::LandmarkTruth& truth) {
  return recorder_.close(filter_, truth);
}

void CcTeamLink::printSummary(std::FILE* out, double duration_s) const {
  const coop::CcTeamStatistics& st = filter_.statistics();
  const TimeSummary steps = summariseTimes(st.step_ms);
  std::fprintf(out,
               "  ground station: %ld batches (%ld refused: %s; %ld vehicle restarts), step median "
               "%.2f ms, p95 %.2f ms, max %.2f ms, state size max %d, joint map %zu landmarks\n",
               st.batches, st.rejected(), st.refusalSummary().c_str(), restarts_, steps.median_ms,
               steps.p95_ms, steps.max_ms, st.max_state_size, filter_.map().size());
  for (const auto& [id, c] : st.agents) {
    const auto sent = bytes_sent_.count(id) > 0 ? bytes_sent_.at(id) : 0;
    std::fprintf(out,
                 "    UAV%d: %ld batches accepted of %ld, %ld IMU gaps bridged, observations type "
                 "1/2/3 %ld/%ld/%ld, %ld loop closures, %.1f KB/s to the ground station\n",
                 id, c.batches, c.batches + c.rejected + dropped(id), c.imu_gaps_bridged, c.type1,
                 c.type2, c.type3, c.loop_closures,
                 duration_s > 0 ? static_cast<double>(sent) / duration_s / 1000.0 : 0.0);
  }
}

}  // namespace cvslam
