#include "cvslam/lcm/lcm_bus.h"

#include <lcm/lcm-cpp.hpp>

#include <utility>

#include "cvslam/lcm/channels.h"

namespace cvslam::transport {
namespace {

// LCM's C entry point. We subscribe through the C API rather than lcm::LCM's
// member-function template: under -fsanitize=undefined the 1.3.1 C++ wrapper hands its
// callback a bad subscription pointer (reproduced with LCM alone), and the C API lets us
// own the handler object's lifetime explicitly.
void onLcmMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user_data) {
  static_cast<SubscriptionBase*>(user_data)->handleBytes(rbuf->data, rbuf->data_size, channel);
}

}  // namespace

Status checkLcmUrl(const std::string& url) {
  for (const char* scheme : {"udpm://", "tcpq://", "memq://", "file://"})
    if (url.rfind(scheme, 0) == 0) return Status::Ok();
  return Status::Error("unsupported LCM URL '" + url + "'");
}

std::function<bool(int32_t)> acceptOnly(std::set<int32_t> agent_ids) {
  return [ids = std::move(agent_ids)](int32_t id) { return ids.count(id) > 0; };
}

LcmBus::LcmBus(BusOptions options) : options_(std::move(options)) {
  if (options_.auth_key) {
    options_.receive.auth_key = options_.auth_key;
    signer_ = std::make_unique<MessageSigner>(*options_.auth_key);
  }
}

Expected<std::unique_ptr<LcmBus>> LcmBus::create(BusOptions options) {
  std::unique_ptr<LcmBus> bus(new LcmBus(std::move(options)));
  bus->lcm_ = std::make_unique<::lcm::LCM>(bus->options_.url);
  if (!bus->lcm_->good()) {
    return Status::Error("cannot open LCM at '" + bus->options_.url +
                         "' (multicast route? see scripts/setup.sh)");
  }
  return bus;
}

LcmBus::~LcmBus() {
  stop();
  lcm_.reset();  // before the subscriptions: LCM holds raw pointers to them
}

Status LcmBus::add(std::unique_ptr<SubscriptionBase> subscription) {
  const std::string& channel = subscription->channel();
  if (!isPlainChannelName(channel) && !isAgentPattern(channel)) {
    return Status::Error("bad channel name '" + channel + "': use [A-Za-z0-9_/] only");
  }
  // LCM's handler table is read by the receive thread without our lock: forbid changes
  // once it runs instead of relying on LCM's internal locking.
  if (running()) return Status::Error("subscribe to " + channel + " after start()");
  lcm_subscription_t* lcm_sub =
      lcm_subscribe(lcm_->getUnderlyingLCM(), channel.c_str(), &onLcmMessage, subscription.get());
  if (lcm_sub == nullptr) return Status::Error("LCM refused the subscription to " + channel);
  lcm_subscription_set_queue_capacity(lcm_sub, options_.lcm_queue_capacity);
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  subscriptions_.push_back(std::move(subscription));
  return Status::Ok();
}

Status LcmBus::publishRaw(const std::string& channel, const void* data, std::size_t size) {
  std::vector<uint8_t> signed_bytes;
  if (signer_ && isSignedChannel(channel)) {
    signed_bytes = signer_->sign(channel, data, size);
    data = signed_bytes.data();
    size = signed_bytes.size();
  }
  if (size > options_.receive.max_message_bytes) {
    return Status::Error("publish " + channel + ": " + std::to_string(size) +
                         " bytes exceed the message size limit");
  }
  if (lcm_->publish(channel, data, static_cast<unsigned int>(size)) != 0) {
    return Status::Error("LCM publish failed on " + channel);
  }
  std::lock_guard<std::mutex> lock(published_mutex_);
  auto& [bytes, messages] = published_[channel];
  bytes += static_cast<int64_t>(size);
  ++messages;
  return Status::Ok();
}

int64_t LcmBus::bytesPublished(const std::string& channel) const {
  std::lock_guard<std::mutex> lock(published_mutex_);
  auto it = published_.find(channel);
  return it == published_.end() ? 0 : it->second.first;
}

std::map<std::string, int64_t> LcmBus::bytesPublishedByChannel() const {
  std::lock_guard<std::mutex> lock(published_mutex_);
  std::map<std::string, int64_t> bytes;
  for (const auto& [channel, counts] : published_) bytes[channel] = counts.first;
  return bytes;
}

int64_t LcmBus::messagesPublished(const std::string& channel) const {
  std::lock_guard<std::mutex> lock(published_mutex_);
  auto it = published_.find(channel);
  return it == published_.end() ? 0 : it->second.second;
}

int64_t LcmBus::nextSeq(const std::string& channel) {
  std::lock_guard<std::mutex> lock(seq_mutex_);
  return next_seq_[channel]++;
}

Status LcmBus::start() {
  if (running()) return Status::Ok();
  stop_requested_ = false;
  thread_ = std::thread([this] { receiveLoop(); });
  return Status::Ok();
}

void LcmBus::stop() {
  stop_requested_ = true;
  if (thread_.joinable()) thread_.join();
}

void LcmBus::receiveLoop() {
  constexpr int kTimeoutMs = 100;  // bounds how long stop() waits
  while (!stop_requested_) {
    if (lcm_->handleTimeout(kTimeoutMs) < 0) {
      if (options_.receive.on_error) {
        options_.receive.on_error("", Status::Error("LCM handleTimeout failed"));
      }
      break;
    }
  }
}

std::vector<ChannelCounters> LcmBus::counters() const {
  std::lock_guard<std::mutex> lock(subscriptions_mutex_);
  std::vector<ChannelCounters> all;
  all.reserve(subscriptions_.size());
  for (const auto& s : subscriptions_) all.push_back(s->counters());
  return all;
}

ChannelCounters LcmBus::counters(const std::string& channel) const {
  ChannelCounters sum;
  sum.channel = channel;
  for (const ChannelCounters& c : counters()) {
    if (c.channel != channel) continue;
    sum.type = sum.type.empty() ? c.type : sum.type;
    sum.received += c.received;
    sum.dropped += c.dropped;
    sum.invalid += c.invalid;
    sum.seq_gaps += c.seq_gaps;
    sum.seq_resets += c.seq_resets;
    sum.unsigned_msgs += c.unsigned_msgs;
    sum.forged += c.forged;
    sum.replayed += c.replayed;
  }
  return sum;
}

}  // namespace cvslam::transport
