#pragma once
// Watches every channel of an LCM network (subscription ".*", raw bytes) and keeps
// per-channel statistics: message count, rate, bandwidth and header.seq gaps per sender,
// read with header_peek.h (only the header is decoded). Used by cvslam_lcm_stats and tests.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>
#include "cvslam/core/status.h"
#include "cvslam/lcm/header_peek.h"

namespace lcm {
class LCM;
}

namespace cvslam::transport {

struct ChannelReport {
  std::string channel;
  std::string type;  ///< cvslam type, or "?" for foreign messages
  int64_t messages = 0;
  int64_t bytes = 0;
  int64_t seq_gaps = 0;        ///< messages missing by header.seq, summed over senders
  int64_t seq_resets = 0;      ///< header.seq went backwards
  int64_t no_header = 0;       ///< messages that are not a cvslam type (no seq check)
  int senders = 0;             ///< distinct header.agent_id values
  double active_s = 0.0;       ///< time between the first and the last message [s]
  double rate_hz = 0.0;        ///< (messages − 1) / active_s; 0 with fewer than 2 messages
  double bandwidth_Bps = 0.0;  ///< bytes / active_s [B/s]; 0 with fewer than 2 messages
};

/// Accumulates statistics; not thread-safe (ChannelMonitor locks around it).
class ChannelStatistics {
 public:
  void add(const std::string& channel, std::size_t bytes, const std::optional<PeekedHeader>& header,
           double arrival_s);
  std::vector<ChannelReport> report() const;

 private:
  struct Channel {
    ChannelReport r;
    double first_s = 0.0, last_s = 0.0;
    std::map<int32_t, int64_t> last_seq;
  };
  std::map<std::string, Channel> channels_;
};

class ChannelMonitor {
 public:
  static Expected<std::unique_ptr<ChannelMonitor>> create(const std::string& url);
  ~ChannelMonitor();
  ChannelMonitor(const ChannelMonitor&) = delete;
  ChannelMonitor& operator=(const ChannelMonitor&) = delete;
  Status start();
  void stop();
  std::vector<ChannelReport> report() const;
  /// Handler body (LCM's receive thread); public for the C callback.
  void onMessage(const std::string& channel, const void* data, std::size_t size);

 private:
  ChannelMonitor() = default;
  std::unique_ptr<::lcm::LCM> lcm_;
  mutable std::mutex mutex_;
  ChannelStatistics stats_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace cvslam::transport
