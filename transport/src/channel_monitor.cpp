#include "cvslam/lcm/channel_monitor.h"

#include <lcm/lcm-cpp.hpp>

namespace cvslam::transport {
namespace {

void onRaw(const lcm_recv_buf_t* rbuf, const char* channel, void* user_data) {
  static_cast<ChannelMonitor*>(user_data)->onMessage(channel, rbuf->data, rbuf->data_size);
}

}  // namespace

void ChannelStatistics::add(const std::string& channel, std::size_t bytes,
                            const std::optional<PeekedHeader>& header, double arrival_s) {
  auto [it, inserted] = channels_.try_emplace(channel);
  Channel& c = it->second;
  if (inserted) {
    c.r.channel = channel;
    c.r.type = header ? header->type : "?";
    c.first_s = arrival_s;
  }
  c.last_s = arrival_s;
  ++c.r.messages;
  c.r.bytes += static_cast<int64_t>(bytes);
  if (!header) {
    ++c.r.no_header;
    return;
  }
  auto last = c.last_seq.find(header->agent_id);
  if (last != c.last_seq.end()) {
    if (header->seq > last->second) {
      c.r.seq_gaps += header->seq - last->second - 1;
    } else {
      ++c.r.seq_resets;
    }
    last->second = header->seq;
  } else {
    // The first message seen from a sender: numbers before it were sent before we listened
    // (seq starts at 0), so they are not counted as gaps.
    c.last_seq[header->agent_id] = header->seq;
  }
}

std::vector<ChannelReport> ChannelStatistics::report() const {
  std::vector<ChannelReport> out;
  for (const auto& [name, c] : channels_) {
    ChannelReport r = c.r;
    r.senders = static_cast<int>(c.last_seq.size());
    r.active_s = c.last_s - c.first_s;
    if (r.messages >= 2 && r.active_s > 0.0) {
      r.rate_hz = static_cast<double>(r.messages - 1) / r.active_s;
      r.bandwidth_Bps = static_cast<double>(r.bytes) / r.active_s;
    }
    out.push_back(r);
  }
  return out;
}

Expected<std::unique_ptr<ChannelMonitor>> ChannelMonitor::create(const std::string& url) {
  std::unique_ptr<ChannelMonitor> m(new ChannelMonitor());
  m->lcm_ = std::make_unique<::lcm::LCM>(url);
  if (!m->lcm_->good()) return Status::Error("cannot open LCM at '" + url + "'");
  lcm_subscription_t* sub = lcm_subscribe(m->lcm_->getUnderlyingLCM(), ".*", &onRaw, m.get());
  if (sub == nullptr) return Status::Error("LCM refused the subscription to .*");
  // Image bursts: a deep queue so LCM's own queue does not drop what the kernel delivered.
  lcm_subscription_set_queue_capacity(sub, 10000);
  return m;
}

ChannelMonitor::~ChannelMonitor() {
  stop();
  lcm_.reset();
}

Status ChannelMonitor::start() {
  if (thread_.joinable()) return Status::Ok();
  stop_ = false;
  thread_ = std::thread([this] {
    while (!stop_) lcm_->handleTimeout(100);
  });
  return Status::Ok();
}

void ChannelMonitor::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void ChannelMonitor::onMessage(const std::string& channel, const void* data, std::size_t size) {
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  const std::optional<PeekedHeader> header = peekHeader(data, size);
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.add(channel, size, header, t);
}

std::vector<ChannelReport> ChannelMonitor::report() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_.report();
}

}  // namespace cvslam::transport
