#include "dc_team_link.h"

#include <type_traits>

#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/coop_convert.h"

namespace cvslam {

namespace {
constexpr int64_t kBootIdBase = 1000;  // deterministic boot ids for in-process runs
}  // namespace

DcTeamLink::DcTeamLink(const std::map<int, coop::DcCooperationOptions>& options_by_agent,
                       const DcLinkLoss& loss)
    : loss_(loss), loss_rng_(loss.seed) {
  for (const auto& [id, options] : options_by_agent)
    agents_[id] = std::make_unique<coop::DcLinkCore>(id, options, kBootIdBase + id);
}

Status DcTeamLink::open(const std::string& run_dir) {
  for (auto& [id, core] : agents_)
    if (Status s = core->openLog(run_dir); !s.ok()) return s;
  return Status::Ok();
}

Status DcTeamLink::afterFrame(int id, const StereoFrameObservations& frame,
                              VisualInertialSlam& slam, AgentRunWriter* writer) {
  auto it = agents_.find(id);
  if (it == agents_.end()) return Status::Error("dc: unknown agent " + std::to_string(id));
  coop::DcLinkCore& self = *it->second;
  coop::CoopOutbox box;
  if (Status s = self.afterFrame(frame, slam, &box); !s.ok()) return s;

  // Each message as on the wire: encoded (bytes counted), decoded and validated again, then
  // handed to its addressee (to < 0: a broadcast, every other agent).
  return transport::forEachOutboxMessage(
      box, id, [&](const std::string&, transport::Stream stream, int to, auto& m) -> Status {
        using Msg = std::decay_t<decltype(m)>;
        Expected<std::vector<uint8_t>> bytes = transport::encodeMessage(m);
        if (!bytes.ok())
          return Status::Error("UAV" + std::to_string(id) + ": " + bytes.status().message());
        const auto n = static_cast<int64_t>(bytes->size());
        self.countSent(transport::streamName(stream), n);
        if (writer != nullptr) writer->addBytesSent(transport::streamName(stream), n);
        Expected<Msg> back = transport::decodeMessage<Msg>(bytes->data(), bytes->size());
        if (!back.ok()) {
          ++decode_failures_;
          return Status::Ok();  // a receiver drops what it cannot decode
        }
        for (auto& [peer, core] : agents_) {
          if (peer == id || (to >= 0 && peer != to)) continue;
          ++deliveries_;
          if (loss_.percent > 0.0 &&
              std::uniform_real_distribution<double>(0.0, 100.0)(loss_rng_) < loss_.percent) {
            ++lost_;
            continue;
          }
          core->receive(transport::toCoopMessage(*back, peer));
        }
        return Status::Ok();
      });
}

void DcTeamLink::printSummary(std::FILE* out, double duration_s) const {
  for (const auto& [id, core] : agents_)
    std::fprintf(out, "  %s\n", core->report(duration_s).c_str());
  if (loss_.percent > 0.0)
    std::fprintf(out, "  link loss %.1f %%: %lld of %lld deliveries lost\n", loss_.percent,
                 static_cast<long long>(lost_), static_cast<long long>(deliveries_));
  if (decode_failures_ > 0)
    std::fprintf(out, "  %lld messages failed to decode\n",
                 static_cast<long long>(decode_failures_));
}

}  // namespace cvslam
