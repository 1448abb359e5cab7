#include "cvslam/lcm/cc_link.h"

#include <chrono>
#include <filesystem>

#include "cvslam/io/run_writer.h"
#include "cvslam/io/time_format.h"
#include "cvslam/lcm/cc_convert.h"
#include "cvslam/lcm/channels.h"

namespace cvslam::transport {
namespace {

using Clock = std::chrono::steady_clock;
/// The ground station's id in headers and on STATUS (header_t.lcm).

}  // namespace

CcLink::CcLink(int self_id, const AgentNodeOptions::Cc& options, std::string out_dir)
    : id_(self_id), o_(options), out_dir_(std::move(out_dir)), builder_(self_id) {
  // Until it is first heard, the ground station counts as alive since the agent's start: a
  // lockstep run's first frames wait for it as all later ones (it may announce after us).
  gs_heard_s_ = now();
}

double CcLink::now() const {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

const char* CcLink::name(Gs gs) {
  switch (gs) {
    case Gs::kFresh:
      return "fresh";
    case Gs::kStale:
      return "stale";
    case Gs::kAbsent:
      return "absent";
  }
  return "";
}

Status CcLink::subscribe(LcmBus& bus) {
  Status s = bus.subscribe<cvslam::gs_state_t>(channels::gsState(id_),
                                               [this](const cvslam::gs_state_t& m) {
                                                 if (m.header.agent_id != kGroundStationId) return;
                                                 std::lock_guard<std::mutex> lock(mutex_);
                                                 latest_ = fromMessage(m);
                                                 gs_heard_s_ = now();
                                                 arrived_.notify_all();
                                               });
  if (!s.ok()) return s;
  return bus.subscribe<cvslam::status_t>(channels::status(kGroundStationId),
                                         [this](const cvslam::status_t& m) {
                                           if (m.header.agent_id != kGroundStationId) return;
                                           std::lock_guard<std::mutex> lock(mutex_);
                                           gs_heard_s_ = now();
                                           refused_ = coop::refusalsOf(m.message, id_);
                                         });
}

Status CcLink::onStart(AgentPipeline& agent, LcmBus& bus, const std::string& filter_name) {
  // The estimate the agent's filter starts from: the ground station starts the vehicle from it
  // (what cvslam_run --mode cc gives CcTeamFilter::addVehicle).
  const VisualInertialSlam& slam = agent.slam();
  cvslam::agent_state_t pose = agentStateMessage(id_, filter_name, slam.time(), slam.vehicleState(),
                                                 slam.vehicleCovariance());
  return bus.publish(channels::pose(id_), pose);
}

Status CcLink::log(int64_t t_us) {
  if (out_dir_.empty()) return Status::Ok();
  if (!log_.is_open()) {
    const std::string dir = agentDir(out_dir_, id_);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    log_.open(dir + "/coop.csv");
    if (!log_) return Status::Error("cannot write " + dir + "/coop.csv");
    log_ << "t,event,frames_adopted,frames_own\n";
  }
  log_ << formatSeconds(static_cast<double>(t_us) * 1e-6) << ",gs_" << name(gs_) << ','
       << frames_adopted_ << ',' << frames_own_ << '\n';
  log_.flush();
  return log_ ? Status::Ok() : Status::Error("coop.csv: write failed");
}

Status CcLink::afterFrame(AgentPipeline& agent, LcmBus& bus,
                          const std::function<void(cvslam::agent_summary_t&)>&) {
  const coop::CcObservationBatch batch = builder_.takeBatch(agent.lastFrame());
  auto msg = toMessage(batch);
  if (!msg.ok()) return msg.status();
  if (Status s = bus.publish(channels::observations(id_), *msg); !s.ok()) return s;
  const int64_t t = batch.t_us;
  Gs gs = Gs::kAbsent;
  adopted_.reset();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    const bool alive = now() - gs_heard_s_ < o_.gs_timeout_s;
    if (alive) {
      const auto deadline = Clock::now() + std::chrono::duration<double>(o_.gs_wait_s);
      arrived_.wait_until(lock, deadline, [&] { return latest_ && latest_->t_us >= t; });
      gs = Gs::kStale;
    }
    if (latest_ && latest_->t_us == t) {
      adopted_ = *latest_;
      gs = Gs::kFresh;
    }
  }
  if (gs == Gs::kFresh) {
    ++frames_adopted_;
  } else {
    ++frames_own_;
  }
  const bool changed = !logged_ || gs != gs_;
  if (changed && gs == Gs::kFresh && logged_) ++takeovers_;
  gs_ = gs;
  if (!changed) return Status::Ok();
  logged_ = true;
  return log(t);
}

std::string CcLink::refused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return refused_;
}

std::string CcLink::statusText() const {
  const std::string r = refused();
  return std::string("gs: ") + name(gs_) + ", adopted " + std::to_string(frames_adopted_) +
         ", own " + std::to_string(frames_own_) +
         (r.empty() ? "" : "; gs refused my batches: " + r);
}

bool CcLink::degraded() const {
  return !refused().empty();
}

std::string CcLink::report() const {
  return "centralised: frames adopted " + std::to_string(frames_adopted_) + ", own " +
         std::to_string(frames_own_) + ", ground station took over " + std::to_string(takeovers_) +
         " time(s) after a gap, last gs " + name(gs_) +
         (refused().empty() ? "" : ", gs refused batches: " + refused());
}

}  // namespace cvslam::transport
