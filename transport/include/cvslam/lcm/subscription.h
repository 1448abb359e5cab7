#pragma once
// One typed subscription of an LcmBus: receives raw LCM buffers on the bus's receive
// thread, decodes and checks them (codec.h), applies the agent filter, tracks sequence
// gaps per sender, and hands valid messages to a bounded queue or a callback. Counters
// are atomics so any thread may read them while the receive thread runs.

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "cvslam/core/status.h"
#include "cvslam/lcm/bounded_queue.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/message_auth.h"

namespace cvslam::transport {

/// Message counts of one subscription. Every arriving buffer is exactly one of
/// received, dropped or invalid.
struct ChannelCounters {
  std::string channel;
  std::string type;        ///< LCM type name, e.g. "imu_t"
  int64_t received = 0;    ///< valid and delivered (queued or passed to the callback)
  int64_t dropped = 0;     ///< valid but the queue was full (the newest message is lost)
  int64_t invalid = 0;     ///< decode or validation failure, or agent not accepted
  int64_t seq_gaps = 0;    ///< messages missing according to header.seq, summed over senders
  int64_t seq_resets = 0;  ///< header.seq went backwards (sender restarted or reordering)
  // Authentication (message_auth.h; also counted as invalid): refused signed-channel messages.
  int64_t unsigned_msgs = 0;  ///< no trailer
  int64_t forged = 0;         ///< the tag does not verify (wrong key, tampered, other channel)
  int64_t replayed = 0;       ///< counter already seen or older than the replay window
};

/// What a subscription needs from its bus; owned by the bus, outlives the subscriptions.
struct ReceivePolicy {
  std::size_t max_message_bytes = kDefaultMaxMessageBytes;
  std::function<bool(int32_t agent_id)> accept_agent;  ///< empty: accept every sender
  std::function<void(const std::string& channel, const Status& error)> on_error;
  /// Set: messages on signed channels must carry a valid trailer (message_auth.h).
  std::shared_ptr<const TeamKey> auth_key;
};

class SubscriptionBase {
 public:
  SubscriptionBase(std::string channel, std::string type, const ReceivePolicy& policy)
      : channel_(std::move(channel)), type_(std::move(type)), policy_(policy) {}
  virtual ~SubscriptionBase() = default;
  SubscriptionBase(const SubscriptionBase&) = delete;
  SubscriptionBase& operator=(const SubscriptionBase&) = delete;

  /// Feeds one encoded buffer as it arrived on `channel` (the subscription's own name when
  /// null) — receive thread only, or tests.
  void handleBytes(const void* data, std::size_t size, const char* channel = nullptr);

  ChannelCounters counters() const;
  const std::string& channel() const { return channel_; }

 protected:
  enum class Outcome { kDelivered, kDropped, kInvalid };
  /// Decodes, checks and delivers; fills agent_id and seq when the message decoded.
  virtual Outcome process(const void* data, std::size_t size, int32_t& agent_id, int64_t& seq,
                          Status& error) = 0;
  const ReceivePolicy& policy() const { return policy_; }

 private:
  void trackSequence(int32_t agent_id, int64_t seq);

  const std::string channel_;
  const std::string type_;
  const ReceivePolicy& policy_;
  /// Strips and checks the trailer of a signed channel's message; false: refused (counted).
  bool authenticate(const uint8_t* data, std::size_t& size, const char* channel);

  std::atomic<int64_t> received_{0}, dropped_{0}, invalid_{0}, seq_gaps_{0}, seq_resets_{0};
  std::atomic<int64_t> unsigned_{0}, forged_{0}, replayed_{0};
  std::map<int32_t, int64_t> last_seq_;  ///< per sender; receive thread only
  std::map<std::pair<std::string, int32_t>, ReplayWindow> windows_;  ///< per channel and sender
};

template <typename Msg>
class TypedSubscription final : public SubscriptionBase {
 public:
  using Callback = std::function<void(const Msg&)>;

  TypedSubscription(std::string channel, const ReceivePolicy& policy,
                    std::shared_ptr<BoundedQueue<Msg>> queue, Callback callback)
      : SubscriptionBase(std::move(channel), Msg::getTypeName(), policy),
        queue_(std::move(queue)),
        callback_(std::move(callback)) {}

 protected:
  Outcome process(const void* data, std::size_t size, int32_t& agent_id, int64_t& seq,
                  Status& error) override {
    Expected<Msg> msg = decodeMessage<Msg>(data, size, policy().max_message_bytes);
    if (!msg.ok()) {
      error = msg.status();
      return Outcome::kInvalid;
    }
    agent_id = msg->header.agent_id;
    seq = msg->header.seq;
    if (policy().accept_agent && !policy().accept_agent(agent_id)) {
      error = Status::Error("message from unexpected agent " + std::to_string(agent_id));
      return Outcome::kInvalid;
    }
    if (queue_) return queue_->tryPush(std::move(*msg)) ? Outcome::kDelivered : Outcome::kDropped;
    try {
      callback_(*msg);
    } catch (const std::exception& e) {
      // A throwing callback must not take the receive thread down; the message counts as
      // delivered because it was valid.
      error = Status::Error(std::string("subscriber callback threw: ") + e.what());
    }
    return Outcome::kDelivered;
  }

 private:
  std::shared_ptr<BoundedQueue<Msg>> queue_;
  Callback callback_;
};

}  // namespace cvslam::transport
