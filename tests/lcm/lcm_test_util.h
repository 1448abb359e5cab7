#pragma once
// Helpers shared by the LCM bus tests.

#include <chrono>
#include <functional>
#include <thread>

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

}  // namespace cvslam::transport::testing
