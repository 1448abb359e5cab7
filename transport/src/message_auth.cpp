#include "cvslam/lcm/message_auth.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>

namespace cvslam::transport {
namespace {

constexpr char kMagic[4] = {'C', 'V', 'A', '1'};
constexpr std::size_t kTagBytes = 32;

void putBigEndian(uint64_t v, uint8_t* out) {
  for (int i = 7; i >= 0; --i, v >>= 8) out[i] = static_cast<uint8_t>(v & 0xff);
}
uint64_t getBigEndian(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

// HMAC-SHA256(key, channel ‖ 0 ‖ encoding ‖ counter): the channel (NUL-terminated, so no
// channel/payload boundary can be shifted) binds the message to where it was sent.
void tag(const TeamKey& key, const std::string& channel, const uint8_t* encoding, std::size_t size,
         const uint8_t counter[8], uint8_t out[kTagBytes]) {
  thread_local std::vector<uint8_t> buffer;
  buffer.clear();
  buffer.insert(buffer.end(), channel.begin(), channel.end());
  buffer.push_back(0);
  buffer.insert(buffer.end(), encoding, encoding + size);
  buffer.insert(buffer.end(), counter, counter + 8);
  unsigned int n = kTagBytes;
  HMAC(EVP_sha256(), key.bytes.data(), static_cast<int>(key.bytes.size()), buffer.data(),
       buffer.size(), out, &n);
}

}  // namespace

bool isSignedChannel(const std::string& channel) {
  const auto id = parseChannel(channel);
  if (!id) return false;
  switch (id->stream) {
    case Stream::kTeamSummary:
    case Stream::kIndex:
    case Stream::kSharedReq:
    case Stream::kShared:
    case Stream::kObs:
    case Stream::kGsState:
    case Stream::kGsMap:
      return true;
    default:
      return false;
  }
}

Expected<TeamKey> TeamKey::readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return Status::Error("cannot read the team key file '" + path + "'");
  TeamKey key;
  key.bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  while (!key.bytes.empty() && (key.bytes.back() == '\n' || key.bytes.back() == '\r'))
    key.bytes.pop_back();
  if (key.bytes.size() < kMinTeamKeyBytes)
    return Status::Error("team key '" + path + "' has " + std::to_string(key.bytes.size()) +
                         " bytes, fewer than " + std::to_string(kMinTeamKeyBytes) +
                         " (make one: head -c 32 /dev/urandom > FILE)");
  return key;
}

Expected<std::shared_ptr<const TeamKey>> TeamKey::forOption(const std::string& path) {
  if (path.empty()) return std::shared_ptr<const TeamKey>();
  Expected<TeamKey> key = readFile(path);
  if (!key.ok()) return key.status();
  return std::make_shared<const TeamKey>(std::move(*key));
}

std::vector<uint8_t> MessageSigner::sign(const std::string& channel, const void* encoding,
                                         std::size_t size) {
  uint64_t counter;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    const auto us =
        static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(now).count());
    counter = last_counter_ = std::max(us, last_counter_ + 1);
  }
  std::vector<uint8_t> out(size + kAuthTrailerBytes);
  std::memcpy(out.data(), encoding, size);
  uint8_t* trailer = out.data() + size;
  std::memcpy(trailer, kMagic, 4);
  putBigEndian(counter, trailer + 4);
  tag(key_, channel, out.data(), size, trailer + 4, trailer + 12);
  return out;
}

const char* authVerdictName(AuthVerdict verdict) {
  switch (verdict) {
    case AuthVerdict::kAccepted:
      return "accepted";
    case AuthVerdict::kUnsigned:
      return "unsigned";
    case AuthVerdict::kForged:
      return "forged";
    case AuthVerdict::kReplayed:
      return "replayed";
  }
  return "";
}

bool ReplayWindow::accept(uint64_t counter) {
  if (!any_ || counter > highest_) {
    const uint64_t shift = any_ ? counter - highest_ : kSize;
    seen_ = shift >= static_cast<uint64_t>(kSize) ? 0 : seen_ << shift;
    seen_ |= 1;
    highest_ = counter;
    any_ = true;
    return true;
  }
  const uint64_t age = highest_ - counter;
  if (age >= static_cast<uint64_t>(kSize)) return false;
  const uint64_t bit = uint64_t{1} << age;
  if (seen_ & bit) return false;
  seen_ |= bit;
  return true;
}

AuthVerdict verifyTrailer(const TeamKey& key, const std::string& channel, const uint8_t* data,
                          std::size_t size, std::size_t* payload_size, uint64_t* counter) {
  if (size < kAuthTrailerBytes) return AuthVerdict::kUnsigned;
  const uint8_t* trailer = data + size - kAuthTrailerBytes;
  if (std::memcmp(trailer, kMagic, 4) != 0) return AuthVerdict::kUnsigned;
  uint8_t expected[kTagBytes];
  tag(key, channel, data, size - kAuthTrailerBytes, trailer + 4, expected);
  if (CRYPTO_memcmp(expected, trailer + 12, kTagBytes) != 0) return AuthVerdict::kForged;
  *payload_size = size - kAuthTrailerBytes;
  *counter = getBigEndian(trailer + 4);
  return AuthVerdict::kAccepted;
}

}  // namespace cvslam::transport
