#include "cvslam/lcm/subscription.h"

namespace cvslam::transport {

void SubscriptionBase::handleBytes(const void* data, std::size_t size) {
  int32_t agent_id = 0;
  int64_t seq = -1;
  Status error;
  const Outcome outcome = process(data, size, agent_id, seq, error);
  switch (outcome) {
    case Outcome::kDelivered:
      ++received_;
      break;
    case Outcome::kDropped:
      ++dropped_;
      break;
    case Outcome::kInvalid:
      ++invalid_;
      break;
  }
  // Dropped messages did arrive: only invalid ones say nothing about the sender's sequence.
  if (outcome != Outcome::kInvalid) trackSequence(agent_id, seq);
  if (!error.ok() && policy_.on_error) policy_.on_error(channel_, error);
}

void SubscriptionBase::trackSequence(int32_t agent_id, int64_t seq) {
  auto it = last_seq_.find(agent_id);
  if (it != last_seq_.end()) {
    if (seq > it->second + 1) seq_gaps_ += seq - it->second - 1;
    if (seq <= it->second) ++seq_resets_;
  }
  last_seq_[agent_id] = seq;
}

ChannelCounters SubscriptionBase::counters() const {
  ChannelCounters c;
  c.channel = channel_;
  c.type = type_;
  c.received = received_.load();
  c.dropped = dropped_.load();
  c.invalid = invalid_.load();
  c.seq_gaps = seq_gaps_.load();
  c.seq_resets = seq_resets_.load();
  return c;
}

}  // namespace cvslam::transport
