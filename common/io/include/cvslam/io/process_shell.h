#pragma once
// What every long-running cvslam process does the same way around its work: stop cleanly on
// SIGINT / SIGTERM, and fail with one line "<program>: <message>" and exit status 2
// (cli.h's rule for command-line errors, kept for every later error too).
//
//   const cvslam::cli::ProcessShell shell("cvslam_view");
//   if (!s.ok()) return shell.fail(s.message());
//   shell.stopOnSignals();
//   while (!shell.stopping()) { … }

#include <atomic>
#include <string>

namespace cvslam::cli {

class ProcessShell {
 public:
  explicit ProcessShell(std::string program) : program_(std::move(program)) {}

  /// Prints "<program>: <message>" on stderr; returns the exit status for main (2).
  int fail(const std::string& message) const;
  /// From now on SIGINT and SIGTERM set the stop flag instead of killing the process.
  void stopOnSignals() const;
  /// True once a stop signal arrived.
  bool stopping() const { return stopFlag().load(); }
  /// The flag itself, for loops that take it (AgentNode::run).
  static std::atomic<bool>& stopFlag();

 private:
  std::string program_;
};

}  // namespace cvslam::cli
