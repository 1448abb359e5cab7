#pragma once
// Typed publish/subscribe over one lcm::LCM (docs/architecture.md; modelled on Drake's LCM layer).
//
// Threading: subscriptions are made before start(); start() launches the single receive
// thread, the only caller of handleTimeout(), which loops with a 100 ms timeout until
// stop() (or the destructor). Each subscription either fills a BoundedQueue the caller
// drains from any thread, or invokes a callback *on the receive thread* — such callbacks
// must be quick and must not call back into the bus's subscribe/start/stop.
// publish() may be called from any thread, before or after start().
//
// Every buffer that arrives is decoded and checked (codec.h); failures and messages from
// agents the policy does not accept are counted as invalid and reported to on_error,
// never thrown. Publishing finalizes the count fields, validates, and stamps header.seq
// per channel (0, 1, 2, ...), so receivers can count gaps.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/lcm/bounded_queue.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/subscription.h"

namespace lcm {
class LCM;
}

namespace cvslam::transport {

/// Default provider: loopback multicast that never leaves the host (docs/architecture.md).
constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

struct BusOptions {
  /// LCM provider URL; "memq://" for in-process tests.
  std::string url = kDefaultLcmUrl;
  /// Receive policy: size limit, agent filter, error sink (called on the receive thread).
  ReceivePolicy receive;
  /// Capacity of LCM's internal per-subscription queue [messages]. LCM drops the newest
  /// message silently when it is full, so keep it large enough for bursts; those losses
  /// show up only as seq_gaps.
  int lcm_queue_capacity = 1000;
  /// Set: messages on the signed channels are signed when published and must verify when
  /// received (message_auth.h); unsigned, forged and replayed ones are dropped and counted.
  std::shared_ptr<const TeamKey> auth_key;
};

/// Ok when `url` names a provider LCM knows (udpm, tcpq, memq, file): checked before LCM,
/// which prints its own complaint about an unknown one.
Status checkLcmUrl(const std::string& url);

/// An agent filter accepting exactly the given ids.
std::function<bool(int32_t)> acceptOnly(std::set<int32_t> agent_ids);

class LcmBus {
 public:
  /// Connects to options.url; fails if LCM cannot be initialised (bad URL, no network).
  static Expected<std::unique_ptr<LcmBus>> create(BusOptions options);
  ~LcmBus();
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  /// Subscribes `channel` (a plain name, see isPlainChannelName, or allAgentsPattern(stream)
  /// for a stream of every agent) with a queue of
  /// `capacity` messages; the caller pops from the returned queue.
  template <typename Msg>
  Expected<std::shared_ptr<BoundedQueue<Msg>>> subscribeQueue(const std::string& channel,
                                                              std::size_t capacity) {
    auto queue = std::make_shared<BoundedQueue<Msg>>(capacity);
    Status status =
        add(std::make_unique<TypedSubscription<Msg>>(channel, options_.receive, queue, nullptr));
    if (!status.ok()) return status;
    return queue;
  }

  /// Subscribes `channel`; `callback` runs on the receive thread for each valid message.
  template <typename Msg>
  Status subscribe(const std::string& channel, std::function<void(const Msg&)> callback) {
    if (!callback) return Status::Error("subscribe: empty callback for " + channel);
    return add(std::make_unique<TypedSubscription<Msg>>(channel, options_.receive, nullptr,
                                                        std::move(callback)));
  }

  /// Finalizes and validates `msg`, sets msg.header.seq to this channel's next number and
  /// publishes it. The caller sets header.utime and header.agent_id.
  template <typename Msg>
  Status publish(const std::string& channel, Msg& msg) {
    if (!isPlainChannelName(channel)) return Status::Error("bad channel name '" + channel + "'");
    msg.header.seq = nextSeq(channel);
    Expected<std::vector<uint8_t>> bytes = encodeMessage(msg);
    if (!bytes.ok()) return bytes.status();
    return publishRaw(channel, bytes->data(), bytes->size());
  }

  /// Publishes bytes as they are (log replay, fault injection in tests); signed like publish()
  /// when the bus has a key and the channel is signed.
  Status publishRaw(const std::string& channel, const void* data, std::size_t size);

  /// Starts the receive thread. Idempotent.
  Status start();
  /// Stops and joins the receive thread (within ~100 ms). Idempotent.
  void stop();
  bool running() const { return thread_.joinable(); }

  /// Payload bytes and messages published on `channel` so far (publish and publishRaw).
  int64_t bytesPublished(const std::string& channel) const;
  int64_t messagesPublished(const std::string& channel) const;
  /// Bytes published per channel so far.
  std::map<std::string, int64_t> bytesPublishedByChannel() const;

  /// Counters of every subscription, in subscription order.
  std::vector<ChannelCounters> counters() const;
  /// Counters summed over the subscriptions of one channel (zero if none).
  ChannelCounters counters(const std::string& channel) const;

 private:
  explicit LcmBus(BusOptions options);
  Status add(std::unique_ptr<SubscriptionBase> subscription);
  int64_t nextSeq(const std::string& channel);
  void receiveLoop();

  BusOptions options_;
  std::unique_ptr<::lcm::LCM> lcm_;
  std::unique_ptr<MessageSigner> signer_;
  mutable std::mutex subscriptions_mutex_;
  std::vector<std::unique_ptr<SubscriptionBase>> subscriptions_;
  std::mutex seq_mutex_;
  std::map<std::string, int64_t> next_seq_;
  mutable std::mutex published_mutex_;
  std::map<std::string, std::pair<int64_t, int64_t>> published_;  // channel -> (bytes, msgs)
  std::atomic<bool> stop_requested_{false};
  std::thread thread_;
};

}  // namespace cvslam::transport
