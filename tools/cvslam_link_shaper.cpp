// cvslam_link_shaper — loss, delay, jitter and a rate limit on the packets an nftables rule
// queues to it (NFQUEUE): `tc netem` in user space, for kernels built without netem
// (docs/transport.md "Multi-host runs"). A thin shell: the decisions are LinkImpairment's;
// this program holds each packet's verdict until its release time.
//
//   nft add rule inet cvlink in iifname eth0 queue num 0
//   cvslam_link_shaper --queue 0 --loss 20 --delay 50 --jitter 10 --seed 7

#include <arpa/inet.h>
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <queue>
#include <string>
#include <vector>

#include "cvslam/io/cli.h"
#include "cvslam/io/process_shell.h"
#include "link_shaper/link_impairment.h"

namespace {

constexpr const char* kUsage =
    R"(usage: cvslam_link_shaper --queue N [--loss PCT] [--delay MS] [--jitter MS] [options]

Shapes the packets that an nftables rule sends to NFQUEUE number N, as `tc netem loss L%
delay D J rate R` would: each packet is dropped with probability PCT %, else let through
after DELAY ± JITTER ms (uniform), serialised at RATE kbit/s first if one is set. For kernels
without netem (scripts/netns_team.sh uses it there). Runs until SIGINT/SIGTERM, then prints
(and writes with --stats-json) what it did. Needs CAP_NET_ADMIN (root).

  --queue N          NFQUEUE number the nftables rule uses (required)
  --loss PCT         loss probability in % (default 0)
  --delay MS         mean added delay [ms] (default 0)
  --jitter MS        delay spread: uniform in delay ± jitter [ms] (default 0)
  --no-reorder       never let a packet overtake an earlier one (default: jitter reorders,
                     as netem does)
  --rate KBIT        link rate [kbit/s], 0 = unlimited (default 0)
  --seed N           seed of the loss and jitter draws (default 1)
  --max-held N       packets held at most; beyond, the kernel drops (default 10000)
  --ready-file F     touch F once the queue is bound (scripts wait for it)
  --stats-json F     write the counters to F at exit
  -h, --help         this text
)";

using Clock = std::chrono::steady_clock;
double nowS() {
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

struct Held {
  double release_s;
  std::uint32_t id;
  bool operator>(const Held& other) const { return release_s > other.release_s; }
};

struct Shaper {
  cvslam::link::LinkImpairment link;
  nfq_q_handle* queue = nullptr;
  std::priority_queue<Held, std::vector<Held>, std::greater<>> held;
  // Counters, reported at exit.
  std::uint64_t packets = 0, dropped = 0, passed = 0, bytes = 0, reordered = 0;
  std::uint64_t verdict_errors = 0, overruns = 0;
  std::size_t max_held = 0;
  double delay_sum_s = 0.0;
  std::uint32_t last_released_id = 0;
  bool released_any = false;

  explicit Shaper(const cvslam::link::LinkImpairmentOptions& o) : link(o) {}

  void verdict(std::uint32_t id, std::uint32_t what) {
    if (nfq_set_verdict(queue, id, what, 0, nullptr) < 0) ++verdict_errors;
  }

  void releaseDue(double now_s) {
    while (!held.empty() && held.top().release_s <= now_s) {
      const Held h = held.top();
      held.pop();
      verdict(h.id, NF_ACCEPT);
      // Packet ids grow with arrival: a smaller id after a larger one overtook nothing, the
      // other way round it was overtaken.
      if (released_any && h.id < last_released_id) ++reordered;
      if (!released_any || h.id > last_released_id) last_released_id = h.id;
      released_any = true;
      ++passed;
    }
  }
};

int onPacket(nfq_q_handle*, nfgenmsg*, nfq_data* data, void* user) {
  auto& s = *static_cast<Shaper*>(user);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(data);
  if (header == nullptr) return 0;
  const std::uint32_t id = ntohl(header->packet_id);
  unsigned char* payload = nullptr;
  const int length = nfq_get_payload(data, &payload);
  const std::size_t bytes = length > 0 ? static_cast<std::size_t>(length) : 0;
  const double now_s = nowS();
  ++s.packets;
  s.bytes += bytes;
  const cvslam::link::LinkDecision d = s.link.decide(now_s, bytes);
  if (d.drop) {
    ++s.dropped;
    s.verdict(id, NF_DROP);
    return 0;
  }
  s.delay_sum_s += d.release_s - now_s;
  s.held.push({d.release_s, id});
  s.max_held = std::max(s.max_held, s.held.size());
  return 0;
}

const cvslam::cli::ProcessShell shell("cvslam_link_shaper");
int fail(const std::string& message) {
  return shell.fail(message);
}

}  // namespace

int main(int argc, char** argv) {
  cvslam::link::LinkImpairmentOptions options;
  unsigned queue_number = 0;
  unsigned max_held = 10000;
  bool no_reorder = false;
  std::string ready_file, stats_file;
  CLI::App app("user-space netem on an NFQUEUE", "cvslam_link_shaper");
  app.add_option("--queue", queue_number)->required()->check(CLI::Range(0, 65535));
  app.add_option("--loss", options.loss_percent)->check(CLI::Range(0.0, 100.0));
  app.add_option("--delay", options.delay_ms)->check(cvslam::cli::kNonNegative);
  app.add_option("--jitter", options.jitter_ms)->check(cvslam::cli::kNonNegative);
  app.add_flag("--no-reorder", no_reorder);
  app.add_option("--rate", options.rate_kbit)->check(cvslam::cli::kNonNegative);
  app.add_option("--seed", options.seed);
  app.add_option("--max-held", max_held)->check(CLI::Range(1u, 1000000u));
  app.add_option("--ready-file", ready_file);
  app.add_option("--stats-json", stats_file);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return *exit_code;
  options.reorder = !no_reorder;
  if (const std::string problem = options.validate(); !problem.empty()) return fail(problem);

  Shaper shaper(options);
  nfq_handle* handle = nfq_open();
  if (handle == nullptr)
    return fail("cannot open the netfilter queue (needs root and nfnetlink_queue)");
  shaper.queue =
      nfq_create_queue(handle, static_cast<std::uint16_t>(queue_number), &onPacket, &shaper);
  if (shaper.queue == nullptr) {
    nfq_close(handle);
    return fail("cannot bind queue " + std::to_string(queue_number) + " (in use, or not root)");
  }
  // The payload length is all we read (rate limit); copy what the header needs at most.
  constexpr unsigned kCopyBytes = 0xffff;
  if (nfq_set_mode(shaper.queue, NFQNL_COPY_PACKET, kCopyBytes) < 0) {
    nfq_destroy_queue(shaper.queue);
    nfq_close(handle);
    return fail("cannot set the queue's copy mode");
  }
  nfq_set_queue_maxlen(shaper.queue, max_held);
  constexpr unsigned kSocketBuffer = 8u << 20;
  nfnl_rcvbufsiz(nfq_nfnlh(handle), kSocketBuffer);
  const int fd = nfq_fd(handle);
  shell.stopOnSignals();
  if (!ready_file.empty() && !std::ofstream(ready_file)) {
    return fail("cannot write " + ready_file);
  }

  std::vector<char> buffer(kCopyBytes + 4096);
  while (!shell.stopping()) {
    const double now_s = nowS();
    shaper.releaseDue(now_s);
    int timeout_ms = 200;  // wake to notice a signal even when idle
    if (!shaper.held.empty()) {
      const double wait_ms = (shaper.held.top().release_s - now_s) * 1000.0;
      timeout_ms = std::clamp(static_cast<int>(std::ceil(wait_ms)), 0, timeout_ms);
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, timeout_ms);
    if (ready <= 0) continue;
    const ssize_t n = recv(fd, buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n < 0) {
      // ENOBUFS: the kernel dropped queue messages we did not read in time; those packets
      // are lost, as on an overrun radio.
      if (errno == ENOBUFS) ++shaper.overruns;
      continue;
    }
    nfq_handle_packet(handle, buffer.data(), static_cast<int>(n));
  }
  // Let what is held go, so a stop does not turn into a burst of loss.
  while (!shaper.held.empty()) {
    shaper.verdict(shaper.held.top().id, NF_ACCEPT);
    shaper.held.pop();
    ++shaper.passed;
  }
  nfq_destroy_queue(shaper.queue);
  nfq_close(handle);

  const double mean_delay_ms =
      shaper.passed > 0 ? 1000.0 * shaper.delay_sum_s / static_cast<double>(shaper.passed) : 0.0;
  char line[512];
  std::snprintf(line, sizeof line,
                "{\"packets\": %llu, \"dropped\": %llu, \"passed\": %llu, \"bytes\": %llu, "
                "\"reordered\": %llu, \"mean_delay_ms\": %.3f, \"max_held\": %zu, "
                "\"overruns\": %llu, \"verdict_errors\": %llu}",
                static_cast<unsigned long long>(shaper.packets),
                static_cast<unsigned long long>(shaper.dropped),
                static_cast<unsigned long long>(shaper.passed),
                static_cast<unsigned long long>(shaper.bytes),
                static_cast<unsigned long long>(shaper.reordered), mean_delay_ms, shaper.max_held,
                static_cast<unsigned long long>(shaper.overruns),
                static_cast<unsigned long long>(shaper.verdict_errors));
  std::printf("cvslam_link_shaper: %s\n", line);
  if (!stats_file.empty() && !(std::ofstream(stats_file) << line << '\n')) {
    return fail("cannot write " + stats_file);
  }
  return 0;
}
