#include "cvslam/io/process_shell.h"

#include <csignal>
#include <cstdio>

namespace cvslam::cli {
namespace {

// Lock-free, so that setting it from a signal handler is well defined.
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void onStopSignal(int) {
  g_stop.store(true);
}

}  // namespace

int ProcessShell::fail(const std::string& message) const {
  std::fprintf(stderr, "%s: %s\n", program_.c_str(), message.c_str());
  return 2;
}

void ProcessShell::stopOnSignals() const {
  std::signal(SIGINT, onStopSignal);
  std::signal(SIGTERM, onStopSignal);
}

std::atomic<bool>& ProcessShell::stopFlag() {
  return g_stop;
}

}  // namespace cvslam::cli
