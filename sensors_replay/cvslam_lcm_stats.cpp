// cvslam_lcm_stats — listens to every LCM channel for a while and reports, per channel,
// message count, rate, bandwidth and header.seq gaps (only the header is decoded:
// transport/include/cvslam/lcm/header_peek.h).
//
//   cvslam_lcm_stats --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --duration 70 --json s.json

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "cvslam/io/json.h"
#include "cvslam/lcm/channel_monitor.h"
#include "cvslam/lcm/lcm_bus.h"

namespace {

constexpr const char* kUsage = R"(usage: cvslam_lcm_stats [--lcm-url URL] --duration S [--json FILE]

Subscribes to every channel (.*) for S seconds (or until Ctrl-C) and prints per
channel: messages, rate [Hz], bandwidth [MB/s], header.seq gaps and resets (per
sender, from the header of cvslam messages; other messages count as no_header).
Rate and bandwidth are over the channel's active span (first to last message).
Image channels need recv_buf_size in the URL (e.g. &recv_buf_size=16777216).
Exit status 0; 1 if any channel had sequence gaps; 2 on bad input.

options:
  --lcm-url URL    LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --duration S     how long to listen [s]                          [required]
  --json FILE      also write the figures as JSON
  --quiet          print nothing (use with --json)
  -h, --help       this text
)";

// The only mutable global: set by SIGINT/SIGTERM.
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

int fail(const std::string& message) {
  std::fprintf(stderr, "cvslam_lcm_stats: %s\n", message.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string url = cvslam::transport::kDefaultLcmUrl, json_path;
  double duration = -1.0;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (arg == "--quiet") {
      quiet = true;
      continue;
    }
    if (i + 1 >= argc) return fail(arg + " needs a value (see --help)");
    const std::string v = argv[++i];
    if (arg == "--lcm-url") {
      url = v;
    } else if (arg == "--json") {
      json_path = v;
    } else if (arg == "--duration") {
      try {
        duration = std::stod(v);
      } catch (const std::exception&) {
        return fail("bad number for --duration: '" + v + "'");
      }
    } else {
      return fail("unknown option " + arg + " (see --help)");
    }
  }
  if (duration <= 0.0) return fail("--duration S (> 0) is required (see --help)");
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  auto monitor = cvslam::transport::ChannelMonitor::create(url);
  if (!monitor.ok()) return fail(monitor.status().message());
  cvslam::Status s = (*monitor)->start();
  if (!s.ok()) return fail(s.message());
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
  while (!g_stop && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  (*monitor)->stop();

  const auto reports = (*monitor)->report();
  int64_t total_gaps = 0;
  cvslam::Json channels = cvslam::Json::object();
  if (!quiet) {
    std::printf("%-20s %-18s %9s %9s %10s %6s %6s %7s\n", "channel", "type", "messages", "rate_Hz",
                "MB/s", "gaps", "resets", "senders");
  }
  for (const auto& r : reports) {
    total_gaps += r.seq_gaps;
    if (!quiet) {
      std::printf("%-20s %-18s %9lld %9.2f %10.4f %6lld %6lld %7d\n", r.channel.c_str(),
                  r.type.c_str(), static_cast<long long>(r.messages), r.rate_hz,
                  r.bandwidth_Bps / 1e6, static_cast<long long>(r.seq_gaps),
                  static_cast<long long>(r.seq_resets), r.senders);
    }
    cvslam::Json c = cvslam::Json::object();
    c.set("type", cvslam::Json::string(r.type));
    c.set("messages", cvslam::Json::number(static_cast<double>(r.messages)));
    c.set("bytes", cvslam::Json::number(static_cast<double>(r.bytes)));
    c.set("rate_hz", cvslam::Json::number(r.rate_hz));
    c.set("bandwidth_bytes_per_s", cvslam::Json::number(r.bandwidth_Bps));
    c.set("active_s", cvslam::Json::number(r.active_s));
    c.set("seq_gaps", cvslam::Json::number(static_cast<double>(r.seq_gaps)));
    c.set("seq_resets", cvslam::Json::number(static_cast<double>(r.seq_resets)));
    c.set("no_header", cvslam::Json::number(static_cast<double>(r.no_header)));
    c.set("senders", cvslam::Json::number(r.senders));
    channels.set(r.channel, std::move(c));
  }
  if (!quiet && reports.empty()) std::printf("(no messages on %s)\n", url.c_str());
  if (!json_path.empty()) {
    cvslam::Json root = cvslam::Json::object();
    root.set("lcm_url", cvslam::Json::string(url));
    root.set("duration_s", cvslam::Json::number(duration));
    root.set("seq_gaps_total", cvslam::Json::number(static_cast<double>(total_gaps)));
    root.set("channels", std::move(channels));
    std::ofstream f(json_path);
    f << root.dump() << '\n';
    if (!f) return fail("cannot write " + json_path);
  }
  return total_gaps > 0 ? 1 : 0;
}
