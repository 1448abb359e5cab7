#include "cvslam/lcm/subscription.h"

#include "cvslam/lcm/header_peek.h"

namespace cvslam::transport {

bool SubscriptionBase::authenticate(const uint8_t* data, std::size_t& size, const char* channel) {
  const std::string name = channel != nullptr ? channel : channel_;
  if (!policy_.auth_key || !isSignedChannel(name)) return true;
  std::size_t payload = 0;
  uint64_t counter = 0;
  AuthVerdict verdict = verifyTrailer(*policy_.auth_key, name, data, size, &payload, &counter);
  if (verdict == AuthVerdict::kAccepted) {
    // The payload is authentic: its header names the sender whose window applies.
    const auto header = peekHeader(data, payload);
    const int32_t sender = header ? header->agent_id : 0;
    if (!windows_[{name, sender}].accept(counter)) verdict = AuthVerdict::kReplayed;
  }
  switch (verdict) {
    case AuthVerdict::kAccepted:
      size = payload;
      return true;
    case AuthVerdict::kUnsigned:
      ++unsigned_;
      break;
    case AuthVerdict::kForged:
      ++forged_;
      break;
    case AuthVerdict::kReplayed:
      ++replayed_;
      break;
  }
  ++invalid_;
  if (policy_.on_error)
    policy_.on_error(channel_, Status::Error(std::string(authVerdictName(verdict)) + " message"));
  return false;
}

void SubscriptionBase::handleBytes(const void* data, std::size_t size, const char* channel) {
  if (!authenticate(static_cast<const uint8_t*>(data), size, channel)) return;
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
  c.unsigned_msgs = unsigned_.load();
  c.forged = forged_.load();
  c.replayed = replayed_.load();
  return c;
}

}  // namespace cvslam::transport
