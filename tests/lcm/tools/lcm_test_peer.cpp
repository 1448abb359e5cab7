// cvslam_lcm_test_peer: the other process of the multi-process LCM tests, and a small
// publisher for checking lcm-spy by hand (scripts/lcm-spy.sh).
//
//   cvslam_lcm_test_peer stream --url U [--agent N] [--seconds S] [--imu-hz H] [--image-hz H]
//       Publishes, paced in real time and in dataset-time order: imu_t on UAV<N>/IMU at
//       imu-hz, a 752×400 mono8 stereo_image_t (2 × 300 800 bytes) on UAV<N>/STEREO and a
//       pose_t on UAV<N>/GT at image-hz, then one status_t on UAV<N>/STATUS whose
//       processed_utime is the last dataset time. Image bytes are (seq + i + side) mod 256
//       so the receiver can check content.
//   cvslam_lcm_test_peer hostile --url U [--agent N]
//       On UAV<N>/IMU, 100 rounds of: a valid imu_t from agent N, one from agent N + 1000,
//       and a buffer of random bytes (half with imu_t's fingerprint), 1 ms apart.
//   cvslam_lcm_test_peer demo --url U [--agent N] [--seconds S]
//       Publishes a pose_t on UAV<N>/GT and an agent_state_t on UAV<N>/POSE at 5 Hz.
//
// Prints one line per channel with the number of messages sent; exit status 0 on success.

#include <chrono>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "cvslam/io/cli.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/lcm_bus.h"

namespace {

using cvslam::Status;
using cvslam::transport::LcmBus;
namespace channels = cvslam::transport::channels;

struct Options {
  std::string mode;
  std::string url = cvslam::transport::kDefaultLcmUrl;
  int agent = 1;
  double seconds = 5.0;
  int imu_hz = 200;
  int image_hz = 20;
};

constexpr const char* kUsage =
    "usage: cvslam_lcm_test_peer stream|hostile|demo --url U [--agent N] [--seconds S] "
    "[--imu-hz H] [--image-hz H]\n";

/// Fills `o`; nullopt to go on, else the exit status (0 after --help, 2 after an error).
std::optional<int> parse(int argc, char** argv, Options& o) {
  CLI::App app("LCM test publisher", "cvslam_lcm_test_peer");
  app.add_option("mode", o.mode)->required()->check(CLI::IsMember({"stream", "hostile", "demo"}));
  app.add_option("--url", o.url);
  app.add_option("--agent", o.agent);
  app.add_option("--seconds", o.seconds)->check(cvslam::cli::kPositive);
  app.add_option("--imu-hz", o.imu_hz)->check(CLI::PositiveNumber);
  app.add_option("--image-hz", o.image_hz)->check(CLI::PositiveNumber);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (o.imu_hz % o.image_hz != 0) {
    std::fprintf(stderr, "cvslam_lcm_test_peer: --imu-hz must be a multiple of --image-hz\n");
    return 2;
  }
  return std::nullopt;
}

cvslam::pose_t makePose(int agent, int64_t utime, double t) {
  cvslam::pose_t p{};
  p.header.utime = utime;
  p.header.agent_id = agent;
  p.position[0] = 10.0 * t;
  p.position[1] = 2.0;
  p.position[2] = -30.0;
  p.quaternion[0] = 1.0;
  p.velocity[0] = 10.0;
  return p;
}

int stream(LcmBus& bus, const Options& o) {
  constexpr int kWidth = 752, kHeight = 400;
  const int64_t imu_period_us = 1000000 / o.imu_hz;
  const int imu_per_image = o.imu_hz / o.image_hz;
  const int64_t ticks = static_cast<int64_t>(o.seconds * o.imu_hz);
  int64_t imu_sent = 0, images_sent = 0, poses_sent = 0;
  cvslam::stereo_image_t image{};
  image.header.agent_id = o.agent;
  image.encoding = cvslam::stereo_image_t::ENCODING_MONO8;
  image.width = image.stride = kWidth;
  image.height = kHeight;
  image.left_data.resize(kWidth * kHeight);
  image.right_data.resize(kWidth * kHeight);

  const auto start = std::chrono::steady_clock::now();
  int64_t utime = 0;
  for (int64_t k = 0; k < ticks; ++k) {
    std::this_thread::sleep_until(start + std::chrono::microseconds(k * imu_period_us));
    utime = 1000000 + k * imu_period_us;
    cvslam::imu_t imu{};
    imu.header.utime = utime;
    imu.header.agent_id = o.agent;
    imu.accel[2] = -9.81;
    imu.gyro[2] = 0.001 * static_cast<double>(k);
    Status s = bus.publish(channels::imu(o.agent), imu);
    if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
    ++imu_sent;
    if (k % imu_per_image != 0) continue;
    image.header.utime = utime;
    for (std::size_t i = 0; i < image.left_data.size(); ++i) {
      image.left_data[i] = static_cast<uint8_t>(images_sent + static_cast<int64_t>(i));
      image.right_data[i] = static_cast<uint8_t>(images_sent + static_cast<int64_t>(i) + 1);
    }
    s = bus.publish(channels::stereo(o.agent), image);
    if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
    ++images_sent;
    cvslam::pose_t pose = makePose(o.agent, utime, static_cast<double>(k) / o.imu_hz);
    s = bus.publish(channels::groundTruth(o.agent), pose);
    if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
    ++poses_sent;
  }
  cvslam::status_t done{};
  done.header.utime = utime;
  done.header.agent_id = o.agent;
  done.processed_utime = utime;
  done.health = cvslam::status_t::HEALTH_OK;
  done.message = "stream complete";
  Status s = bus.publish(channels::status(o.agent), done);
  if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
  std::printf("%s %lld\n%s %lld\n%s %lld\n%s 1\n", channels::imu(o.agent).c_str(),
              static_cast<long long>(imu_sent), channels::stereo(o.agent).c_str(),
              static_cast<long long>(images_sent), channels::groundTruth(o.agent).c_str(),
              static_cast<long long>(poses_sent), channels::status(o.agent).c_str());
  return 0;
}

int hostile(LcmBus& bus, const Options& o) {
  constexpr int kRounds = 100;
  std::mt19937 rng(12345);
  const std::string channel = channels::imu(o.agent);
  for (int k = 0; k < kRounds; ++k) {
    cvslam::imu_t imu{};
    imu.header.utime = 1000 * k;
    imu.header.agent_id = o.agent;
    imu.accel[2] = -9.81;
    Status s = bus.publish(channel, imu);
    // A sender the receiver does not know. Raw, so it does not use up a sequence number
    // of this channel and the valid sender's sequence stays gap-free.
    imu.header.agent_id = o.agent + 1000;
    const auto stranger = cvslam::transport::encodeMessage(imu);
    if (s.ok())
      s = stranger.ok() ? bus.publishRaw(channel, stranger->data(), stranger->size())
                        : stranger.status();
    std::vector<uint8_t> junk(rng() % 200);
    for (auto& b : junk) b = static_cast<uint8_t>(rng());
    if (junk.size() >= 8 && k % 2 == 0) {
      const int64_t hash = cvslam::imu_t::getHash();
      for (int i = 0; i < 8; ++i) junk[i] = static_cast<uint8_t>(hash >> (56 - 8 * i));
      junk.resize(8 + 20 + 48 + 1);  // one byte too long for an imu_t
    }
    if (s.ok()) s = bus.publishRaw(channel, junk.data(), junk.size());
    if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::printf("%s %d valid, %d unknown agent, %d junk\n", channel.c_str(), kRounds, kRounds,
              kRounds);
  return 0;
}

int demo(LcmBus& bus, const Options& o) {
  const int n = static_cast<int>(o.seconds * 5);
  for (int k = 0; k < n; ++k) {
    const double t = 0.2 * k;
    const auto utime = static_cast<int64_t>(1000000 + 200000 * k);
    cvslam::pose_t pose = makePose(o.agent, utime, t);
    cvslam::agent_state_t state{};
    state.header.utime = utime;
    state.header.agent_id = o.agent;
    state.filter = "nhinf";
    state.state.assign(9, 0.0);
    state.state[0] = pose.position[0];
    state.state[2] = pose.position[2];
    state.state[3] = 10.0;
    state.covariance.assign(81, 0.0);
    for (int i = 0; i < 9; ++i) state.covariance[i * 10] = 0.01;
    state.num_landmarks = 20;
    Status s = bus.publish(channels::groundTruth(o.agent), pose);
    if (s.ok()) s = bus.publish(channels::pose(o.agent), state);
    if (!s.ok()) return std::fprintf(stderr, "peer: %s\n", s.message().c_str()), 1;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  std::printf("%s %d\n%s %d\n", channels::groundTruth(o.agent).c_str(), n,
              channels::pose(o.agent).c_str(), n);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (auto exit_code = parse(argc, argv, o)) return *exit_code;
  cvslam::transport::BusOptions options;
  options.url = o.url;
  auto bus = LcmBus::create(options);
  if (!bus.ok()) {
    std::fprintf(stderr, "peer: %s\n", bus.status().message().c_str());
    return 1;
  }
  if (o.mode == "stream") return stream(**bus, o);
  if (o.mode == "hostile") return hostile(**bus, o);
  return demo(**bus, o);
}
