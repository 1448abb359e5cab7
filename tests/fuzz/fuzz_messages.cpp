// The long fuzz of the message decoders and the receive path (docs/transport.md "Fuzzing"),
// outside CI: N random and mutated buffers per message type (tests/lcm/message_mutator.h),
// each through decodeMessage (the oracle) and through a real subscription's receive path
// (SubscriptionBase::handleBytes: size limit, authentication, decode, validation, counters),
// both unsigned and, on a signed channel with a team key, signed-then-mutated. Built with
// AddressSanitizer and UndefinedBehaviorSanitizer (any report aborts); checks that every buffer
// is counted exactly once and accepted only when it is a valid message. The CI runs a short
// version (tests/lcm/test_fuzz.cpp); this one: scripts/fuzz_messages.sh.
//
//   cvslam_fuzz_messages [--count N] [--seed S]

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "cvslam/lcm/message_auth.h"
#include "cvslam/lcm/subscription.h"
#include "lcm/message_mutator.h"

namespace {

using namespace cvslam::transport;
namespace mut = cvslam::transport::testing;
using mut::alwaysInvalid;
using mut::kMutationKinds;
using mut::Mutation;

struct Totals {
  long long buffers = 0, accepted = 0, failures = 0;
};

template <typename Msg>
void fuzzType(long long count, std::mt19937& rng, const std::shared_ptr<const TeamKey>& key,
              Totals& totals) {
  ReceivePolicy plain, authenticated;
  authenticated.auth_key = key;
  long long delivered = 0;
  auto on = [&delivered](const Msg&) { ++delivered; };
  TypedSubscription<Msg> open_sub("FUZZ", plain, nullptr, on);
  TypedSubscription<Msg> signed_sub("TEAM/SUMMARY", authenticated, nullptr, on);
  MessageSigner signer(*key);
  long long expected_open = 0, expected_signed = 0;
  for (long long i = 0; i < count; ++i) {
    const auto kind = static_cast<Mutation>(i % kMutationKinds);
    std::vector<uint8_t> b = mut::mutate<Msg>(kind, rng);
    const bool valid = decodeMessage<Msg>(b.data(), b.size()).ok();
    if (valid && alwaysInvalid(kind)) {
      std::fprintf(stderr, "%s: mutation %d gave a valid message\n", Msg::getTypeName(),
                   static_cast<int>(kind));
      ++totals.failures;
    }
    open_sub.handleBytes(b.data(), b.size());
    expected_open += valid ? 1 : 0;
    // Signed, then (every other buffer) one more byte changed anywhere, trailer included.
    std::vector<uint8_t> s = signer.sign("TEAM/SUMMARY", b.data(), b.size());
    const bool tampered = (i & 1) != 0;
    if (tampered) s[std::uniform_int_distribution<std::size_t>(0, s.size() - 1)(rng)] ^= 0x5a;
    signed_sub.handleBytes(s.data(), s.size(), "TEAM/SUMMARY");
    expected_signed += valid && !tampered ? 1 : 0;
  }
  const ChannelCounters o = open_sub.counters(), g = signed_sub.counters();
  const bool counted = o.received + o.invalid == count && g.received + g.invalid == count;
  if (o.received != expected_open || g.received != expected_signed || !counted) {
    std::fprintf(stderr,
                 "%s: accepted %lld (expected %lld), signed %lld (expected %lld), counted %d\n",
                 Msg::getTypeName(), static_cast<long long>(o.received), expected_open,
                 static_cast<long long>(g.received), expected_signed, counted ? 1 : 0);
    ++totals.failures;
  }
  totals.buffers += 2 * count;
  totals.accepted += delivered;
  std::printf(
      "  %-22s %lld buffers: %lld valid unsigned, %lld valid signed; refused signed: "
      "forged %lld, unsigned %lld, replayed %lld\n",
      Msg::getTypeName(), 2 * count, static_cast<long long>(o.received),
      static_cast<long long>(g.received), static_cast<long long>(g.forged),
      static_cast<long long>(g.unsigned_msgs), static_cast<long long>(g.replayed));
  std::fflush(stdout);
}

template <typename... Msgs>
void fuzzAll(::testing::Types<Msgs...>*, long long count, std::mt19937& rng,
             const std::shared_ptr<const TeamKey>& key, Totals& totals) {
  (fuzzType<Msgs>(count, rng, key, totals), ...);
}

}  // namespace

int main(int argc, char** argv) {
  long long count = 1000000;
  unsigned seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    char* end = nullptr;
    if ((a == "--count" || a == "--seed") && i + 1 < argc) {
      const long long v = std::strtoll(argv[++i], &end, 10);
      if (*end != '\0' || v < 1) {
        std::fprintf(stderr, "cvslam_fuzz_messages: %s wants a positive integer\n", a.c_str());
        return 2;
      }
      if (a == "--count")
        count = v;
      else
        seed = static_cast<unsigned>(v);
    } else if (a == "-h" || a == "--help") {
      std::puts("usage: cvslam_fuzz_messages [--count N (per type, default 1000000)] [--seed S]");
      return 0;
    } else {
      std::fprintf(stderr, "cvslam_fuzz_messages: unknown option '%s' (try --help)\n", a.c_str());
      return 2;
    }
  }
  auto key = std::make_shared<TeamKey>();
  key->bytes.assign(32, 0x42);
  std::mt19937 rng(seed);
  Totals totals;
  const auto t0 = std::chrono::steady_clock::now();
  std::printf("cvslam_fuzz_messages: %lld buffers per type and path, seed %u\n", count, seed);
  fuzzAll(static_cast<mut::AllMessageTypes*>(nullptr), count, rng, key, totals);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("cvslam_fuzz_messages: %lld buffers in %.0f s, %lld accepted, %lld failures\n",
              totals.buffers, s, totals.accepted, totals.failures);
  return totals.failures == 0 ? 0 : 1;
}
