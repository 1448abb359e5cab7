#include "cvslam/coop/cc_event_orderer.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace cvslam::coop {

CcEventOrderer::CcEventOrderer(const std::vector<int>& expected_agents, double agent_timeout_s,
                               double now_s)
    : expected_(expected_agents.begin(), expected_agents.end()), timeout_s_(agent_timeout_s) {
  for (int id : expected_) heard_[id].last_heard_s = now_s;
}

bool CcEventOrderer::heardAll() const {
  for (const auto& [id, a] : heard_)
    if (!a.ever_heard) return false;
  return true;
}

void CcEventOrderer::heard(int agent_id, double now_s) {
  if (!expects(agent_id)) return;
  Agent& a = heard_[agent_id];
  a.last_heard_s = now_s;
  a.ever_heard = true;
  a.expired = false;
}

void CcEventOrderer::progress(int agent_id, int64_t t_us, double now_s) {
  if (!expects(agent_id)) return;
  heard(agent_id, now_s);
  Agent& a = heard_[agent_id];
  a.progress_us = std::max(a.progress_us, t_us);
}

CcEventOrderer::Push CcEventOrderer::push(CcEvent event, double now_s) {
  if (!expects(event.agent_id)) return Push::kUnknownAgent;
  // A start at t sorts before the agent's batch at t, which is still to come: it finishes
  // only what precedes t (else another agent's batch at t could pass that batch).
  progress(event.agent_id, event.kind == CcEvent::Kind::kStart ? event.t_us - 1 : event.t_us,
           now_s);
  Agent& a = heard_[event.agent_id];
  if (event.kind == CcEvent::Kind::kBatch) {
    if (event.t_us <= a.last_batch_us) return Push::kStale;
    a.last_batch_us = event.t_us;
  }
  const Key key{event.t_us, event.agent_id, static_cast<int>(event.kind)};
  if (queue_.count(key) > 0) return Push::kStale;  // a second start at the same time
  queue_.emplace(key, std::move(event));
  return Push::kQueued;
}

void CcEventOrderer::restart(int agent_id) {
  auto it = heard_.find(agent_id);
  if (it == heard_.end()) return;
  it->second.last_batch_us = -1;
  it->second.progress_us = -1;
}

bool CcEventOrderer::live(int agent_id, double now_s) const {
  auto it = heard_.find(agent_id);
  return it != heard_.end() && !it->second.expired && now_s - it->second.last_heard_s < timeout_s_;
}

bool CcEventOrderer::pop(double now_s, bool flush, CcEvent* out) {
  if (queue_.empty()) return false;
  auto first = queue_.begin();
  const int64_t t = std::get<0>(first->first);
  const int agent = std::get<1>(first->first);
  if (!flush) {
    for (const auto& [id, a] : heard_) {
      if (id == agent || !live(id, now_s)) continue;
      if (a.progress_us < t) return false;  // it may still send something older
    }
  }
  *out = std::move(first->second);
  queue_.erase(first);
  released_us_ = std::max(released_us_, t);
  return true;
}

std::vector<int> CcEventOrderer::expire(double now_s) {
  std::vector<int> gone;
  for (auto& [id, a] : heard_) {
    if (a.expired || now_s - a.last_heard_s < timeout_s_) continue;
    a.expired = true;
    gone.push_back(id);
  }
  return gone;
}

int64_t CcEventOrderer::processedUpTo(double now_s) const {
  int64_t t = std::numeric_limits<int64_t>::max();
  bool any = false;
  for (const auto& [id, a] : heard_) {
    if (!live(id, now_s)) continue;
    t = std::min(t, a.progress_us);
    any = true;
  }
  if (!queue_.empty()) {
    t = std::min(t, std::get<0>(queue_.begin()->first) - 1);
    any = true;
  }
  return any ? std::max<int64_t>(t, -1) : released_us_;
}

}  // namespace cvslam::coop
