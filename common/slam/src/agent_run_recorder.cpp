#include "cvslam/slam/agent_run_recorder.h"

#include <cmath>

#include "cvslam/ins/vehicle_state_layout.h"
#include "cvslam/io/time_format.h"

namespace cvslam {

Status AgentRunRecorder::open(const std::string& run_dir, int agent_id, bool images) {
  writer_ = std::make_unique<AgentRunWriter>();
  if (Status s = writer_->open(run_dir, agent_id); !s.ok()) {
    writer_.reset();
    return s;
  }
  dir_ = agentDir(run_dir, agent_id);
  events_.open(dir_ + "/events.csv", std::ios::trunc);
  if (!events_) return Status::Error("cannot write " + dir_ + "/events.csv");
  events_ << "t,observations,updated,rejected,initialised,archived,reactivated,"
             "loop_landmarks,loop_closure,loop_refused,theta_reduced,state_size,nis,nis_dof\n";
  if (images) return openFrontend();
  return Status::Ok();
}

Status AgentRunRecorder::openFrontend() {
  frontend_.open(dir_ + "/frontend.csv", std::ios::trunc);
  if (!frontend_) return Status::Error("cannot write " + dir_ + "/frontend.csv");
  frontend_ << "t,observations,predictions,gated_pairs,associated,initialised,front_end_ms,"
               "association_ms,filter_ms,loop_candidates,loop_inliers\n";
  return Status::Ok();
}

Status AgentRunRecorder::addFrame(const AgentPipeline& agent, const Vector9d* truth,
                                  double latency_ms) {
  return addFrame(agent, truth, latency_ms, nullptr);
}

Status AgentRunRecorder::addFrame(const AgentPipeline& agent, const Vector9d* truth,
                                  double latency_ms, const VehicleEstimate* adopted) {
  if (!writer_) return Status::Error("AgentRunRecorder: not open");
  const AgentFrame& f = agent.lastFrame();
  const FrameReport& report = f.report;
  const VisualInertialSlam& slam = agent.slam();
  const double t = static_cast<double>(f.t_us) * 1e-6;
  if (f.visual != nullptr && !frontend_.is_open())
    if (Status s = openFrontend(); !s.ok()) return s;
  if (f.visual != nullptr) {
    const VisualFrameResult& r = *f.visual;
    frontend_ << formatSeconds(t) << ',' << r.frame.observations.size() << ',' << r.predictions
              << ',' << r.association.candidates_gated << ',' << r.association.associated << ','
              << r.initialised.size() << ',' << r.front_end_ms << ',' << r.association_ms << ','
              << r.filter_ms << ',' << r.loop.candidates << ',' << r.loop.inliers << '\n';
    writer_->addStageTime("front_end", r.front_end_ms);
    writer_->addStageTime("front_end.detect", r.front_end.detect_ms);
    writer_->addStageTime("front_end.stereo", r.front_end.stereo_ms);
    writer_->addStageTime("front_end.describe", r.front_end.describe_ms);
    writer_->addStageTime("front_end.index", r.front_end.index_ms);
    writer_->addStageTime("association", r.association_ms);
    writer_->addStageTime("filter", r.filter_ms);
  }
  writer_->addStageTime("frame", f.time_ms);
  writer_->addStageTime("filter.predict", report.predict_ms);
  writer_->addStageTime("filter.map", report.map_ms);
  writer_->addStageTime("filter.update", report.update_ms);
  writer_->addStageTime("filter.initialise", report.initialise_ms);
  const Eigen::VectorXd x = adopted != nullptr ? adopted->x_v : slam.vehicleState();
  const Eigen::MatrixXd P = adopted != nullptr ? adopted->P_v : slam.vehicleCovariance();
  if (Status s = writer_->addState(t, x.head<9>(), P.topLeftCorner<9, 9>()); !s.ok()) return s;
  if (x.size() >= vehicle::size(true) && P.rows() >= vehicle::size(true)) {
    const Status s =
        writer_->addBiases(t, x.segment<6>(vehicle::kAccelBias),
                           P.block<6, 6>(vehicle::kAccelBias, vehicle::kAccelBias), bias_truth_);
    bias_truth_.setConstant(std::numeric_limits<double>::quiet_NaN());
    if (!s.ok()) return s;
  }
  if (truth != nullptr)
    if (Status s = writer_->addTruth(t, *truth); !s.ok()) return s;
  if (Status s = writer_->addInsState(t, agent.insState().head<9>()); !s.ok()) return s;
  FrameStats fs;
  fs.t = t;
  fs.time_ms = f.time_ms;
  fs.state_size = report.state_size;
  fs.landmarks = report.landmarks_in_state;
  fs.latency_ms = latency_ms;
  double sigma_sum = 0.0;
  int n_lm = 0;
  for (const StateVariable& v : slam.state().variables()) {
    if (v.key.kind != VariableKey::Kind::kLandmark) continue;
    sigma_sum += std::sqrt(slam.state().covarianceOf(v).trace() / 3.0);
    ++n_lm;
  }
  if (n_lm > 0) fs.landmark_sigma_mean_m = sigma_sum / n_lm;
  writer_->addFrame(fs);
  events_ << formatSeconds(t) << ',' << report.observations << ',' << report.updated << ','
          << report.rejected << ',' << report.initialised << ',' << report.archived << ','
          << report.reactivated << ',' << report.loop_landmarks << ','
          << (report.loop_closure ? 1 : 0) << ',' << (report.loop_refused ? 1 : 0) << ','
          << (report.theta_reduced ? 1 : 0) << ',' << report.state_size << ',' << report.nis << ','
          << report.nis_dof << '\n';
  return events_ ? Status::Ok() : Status::Error(dir_ + "/events.csv: write failed");
}

std::vector<LandmarkRecord> landmarkRecords(
    const std::vector<MapLandmark>& map,
    const std::function<bool(int64_t landmark_id, Eigen::Vector3d* p_LinN)>& truth) {
  std::vector<LandmarkRecord> records;
  for (const MapLandmark& m : map) {
    LandmarkRecord r;
    r.id = m.id;
    r.p_LinN = m.p_LinN;
    r.var = m.covariance.diagonal();
    Eigen::Vector3d p_true;
    if (truth && truth(m.id, &p_true)) r.truth = p_true;
    records.push_back(r);
  }
  return records;
}

Status AgentRunRecorder::writeMap(const VisualInertialSlam& slam, const LandmarkTruth& truth) {
  if (!writer_) return Status::Error("AgentRunRecorder: not open");
  return writer_->writeLandmarks(landmarkRecords(slam.map(), truth));
}

Status AgentRunRecorder::flush() {
  if (!writer_) return Status::Error("AgentRunRecorder: not open");
  events_.flush();
  if (frontend_.is_open()) frontend_.flush();
  return writer_->flush();
}

Status AgentRunRecorder::close() {
  if (!writer_) return Status::Ok();
  events_.close();
  if (frontend_.is_open()) frontend_.close();
  Status s = writer_->close();
  return s;
}

}  // namespace cvslam
