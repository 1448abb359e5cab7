#pragma once
// Helpers shared by the LCM bus tests.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

#include "cvslam/lcm/codec.h"

namespace cvslam::transport::testing {

/// Polls `done` every millisecond until it holds or `timeout` passes; returns its value.
inline bool waitFor(const std::function<bool()>& done,
                    std::chrono::milliseconds timeout = std::chrono::milliseconds(5000)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

/// Encodes and decodes `msg` (an lcmtype) as a receiver would, expecting both to succeed.
template <typename Msg>
Msg throughWire(Msg msg) {
  Expected<std::vector<uint8_t>> bytes = encodeMessage(msg);
  EXPECT_TRUE(bytes.ok()) << bytes.status().message();
  Expected<Msg> back = decodeMessage<Msg>(bytes->data(), bytes->size());
  EXPECT_TRUE(back.ok()) << back.status().message();
  return *back;
}

}  // namespace cvslam::transport::testing
