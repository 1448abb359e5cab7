// cvslam_lcm_stats — listens to every LCM channel for a while and reports, per channel,
// message count, rate, bandwidth and header.seq gaps (only the header is decoded:
// transport/include/cvslam/lcm/header_peek.h).
//
//   cvslam_lcm_stats --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --duration 70 --json s.json

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "cvslam/io/cli.h"
#include "cvslam/io/json_file.h"
#include "cvslam/io/process_shell.h"
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

const cvslam::cli::ProcessShell shell("cvslam_lcm_stats");
int fail(const std::string& message) {
  return shell.fail(message);
}

}  // namespace

int main(int argc, char** argv) {
  std::string url = cvslam::transport::kDefaultLcmUrl, json_path;
  double duration = -1.0;
  bool quiet = false;
  CLI::App app("per-channel LCM statistics", "cvslam_lcm_stats");
  app.add_option("--lcm-url", url);
  app.add_option("--duration", duration)->required()->check(cvslam::cli::kPositive);
  app.add_option("--json", json_path);
  app.add_flag("--quiet", quiet);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  shell.stopOnSignals();

  auto monitor = cvslam::transport::ChannelMonitor::create(url);
  if (!monitor.ok()) return fail(monitor.status().message());
  cvslam::Status s = (*monitor)->start();
  if (!s.ok()) return fail(s.message());
  // Subscribed: say so, so that scripts and tests can start publishing on this event.
  std::fprintf(stderr, "cvslam_lcm_stats: listening on %s for %g s\n", url.c_str(), duration);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
  while (!shell.stopping() && std::chrono::steady_clock::now() < end)
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
    cvslam::Json& c = channels[r.channel];
    c["type"] = r.type;
    c["messages"] = r.messages;
    c["bytes"] = r.bytes;
    c["rate_hz"] = r.rate_hz;
    c["bandwidth_bytes_per_s"] = r.bandwidth_Bps;
    c["active_s"] = r.active_s;
    c["seq_gaps"] = r.seq_gaps;
    c["seq_resets"] = r.seq_resets;
    c["no_header"] = r.no_header;
    c["senders"] = r.senders;
  }
  if (!quiet && reports.empty()) std::printf("(no messages on %s)\n", url.c_str());
  if (!json_path.empty()) {
    cvslam::Json root = cvslam::Json::object();
    root["lcm_url"] = url;
    root["duration_s"] = duration;
    root["seq_gaps_total"] = total_gaps;
    root["channels"] = std::move(channels);
    if (cvslam::Status w = cvslam::writeJsonFile(json_path, root); !w.ok())
      return fail(w.message());
  }
  return total_gaps > 0 ? 1 : 0;
}
