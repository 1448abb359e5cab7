// What authentication costs per message (transport/…/message_auth.h, docs/transport.md):
// HMAC-SHA256 signing and verification of cooperation messages of typical sizes — a summary (~250
// B), a landmark answer (~2 KB), an image-mode observation batch (~25 KB).
#include <benchmark/benchmark.h>

#include <vector>

#include "cvslam/lcm/message_auth.h"

namespace {

using cvslam::transport::MessageSigner;
using cvslam::transport::TeamKey;

TeamKey teamKey() {
  TeamKey k;
  k.bytes.assign(32, 0x5a);
  return k;
}

void BM_Sign(benchmark::State& state) {
  MessageSigner signer(teamKey());
  const std::vector<uint8_t> message(static_cast<std::size_t>(state.range(0)), 0x33);
  for (auto _ : state)
    benchmark::DoNotOptimize(signer.sign("TEAM/SUMMARY", message.data(), message.size()));
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Sign)->Arg(250)->Arg(2000)->Arg(25000);

void BM_Verify(benchmark::State& state) {
  MessageSigner signer(teamKey());
  const TeamKey key = teamKey();
  const std::vector<uint8_t> message(static_cast<std::size_t>(state.range(0)), 0x33);
  const auto sent = signer.sign("TEAM/SUMMARY", message.data(), message.size());
  std::size_t payload = 0;
  uint64_t counter = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(cvslam::transport::verifyTrailer(key, "TEAM/SUMMARY", sent.data(),
                                                              sent.size(), &payload, &counter));
  state.SetBytesProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Verify)->Arg(250)->Arg(2000)->Arg(25000);

}  // namespace

BENCHMARK_MAIN();
