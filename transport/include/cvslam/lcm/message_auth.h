#pragma once
// Authenticated cooperation messages (docs/transport.md "Authentication"): each message on a
// cooperation channel carries, after its LCM encoding, a 44-byte trailer
//   "CVA1" | counter (uint64, big-endian) | HMAC-SHA256(team key, channel ‖ encoding ‖ counter)
// so lcm-spy still decodes the message (the tag travels beside the payload), a tampered, forged
// (wrong key) or moved-to-another-channel message fails the tag, and a replayed one fails the
// counter: per (channel, sender) the receiver accepts a counter above the highest seen, or one
// of the 64 below it not seen yet (reordering on a lossy link), like IPsec's anti-replay window.
// Counters are the sender's clock in microseconds made strictly increasing, so a restarted
// sender goes on above its old counters. Signed channels: TEAM/SUMMARY, UAV<id>/INDEX,
// /SHARED_REQ, /SHARED, /OBS, /GS_STATE and GS/MAP; sensor streams, POSE, STATUS and MAP stay on
// the vehicle (or are for display) and are not signed.
//
// Keys: a file with at least 16 bytes (e.g. `head -c 32 /dev/urandom > team.key`), the same on
// every member of the team; OpenSSL's libcrypto computes the HMAC.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/lcm/channels.h"

namespace cvslam::transport {

constexpr std::size_t kAuthTrailerBytes = 4 + 8 + 32;
constexpr std::size_t kMinTeamKeyBytes = 16;

/// True for the channels whose messages are signed (above).
bool isSignedChannel(const std::string& channel);

struct TeamKey {
  std::vector<uint8_t> bytes;
  /// Reads a key file: at least kMinTeamKeyBytes bytes (a trailing newline is not part of it).
  static Expected<TeamKey> readFile(const std::string& path);
  /// The key of a process's --auth-key: readFile(path) shared, or null (unsigned) for "".
  static Expected<std::shared_ptr<const TeamKey>> forOption(const std::string& path);
};

/// Signs outgoing messages. Thread-safe.
class MessageSigner {
 public:
  explicit MessageSigner(TeamKey key) : key_(std::move(key)) {}
  /// `encoding` followed by its trailer.
  std::vector<uint8_t> sign(const std::string& channel, const void* encoding, std::size_t size);

 private:
  TeamKey key_;
  std::mutex mutex_;
  uint64_t last_counter_ = 0;
};

/// Which messages a receiver accepted or refused, and why.
enum class AuthVerdict { kAccepted, kUnsigned, kForged, kReplayed };
const char* authVerdictName(AuthVerdict verdict);

/// The anti-replay window of one (channel, sender).
class ReplayWindow {
 public:
  static constexpr int kSize = 64;
  /// True (and remembered) for a counter not seen yet and not older than the window.
  bool accept(uint64_t counter);

 private:
  uint64_t highest_ = 0;
  uint64_t seen_ = 0;  ///< bit i: highest_ − i was seen
  bool any_ = false;
};

/// Checks the trailer of a message received on `channel` with `key`. On kForged and kUnsigned
/// nothing is known of the sender; on success `*payload_size` is the encoding's size and
/// `*counter` its counter (the caller applies the sender's ReplayWindow, after decoding who
/// sent it from the now authentic payload).
AuthVerdict verifyTrailer(const TeamKey& key, const std::string& channel, const uint8_t* data,
                          std::size_t size, std::size_t* payload_size, uint64_t* counter);

}  // namespace cvslam::transport
