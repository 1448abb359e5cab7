#pragma once
// Child processes for the replay tests: posix_spawn with stdout and stderr captured to
// files, killed by pid if a test ends early.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace cvslam::test {

class Child {
 public:
  /// Starts args[0] with args; output goes to `log_prefix`.out / .err.
  Child(const std::vector<std::string>& args, const std::string& log_prefix)
      : out_(log_prefix + ".out"), err_(log_prefix + ".err") {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  /// True once the child has ended (reaps it and keeps its status for wait()).
  bool exited() {
    int status = 0;
    if (!exited_ && waitpid(pid_, &status, WNOHANG) == pid_) {
      exited_ = true;
      status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    return exited_;
  }
  /// Exit status, or -1 on timeout or abnormal end.
  int wait(std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (exited()) return status_;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  std::string out() const { return slurp(out_); }
  std::string err() const { return slurp(err_); }

 private:
  static std::string slurp(const std::string& path) {
    std::ifstream f(path);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  std::string out_, err_;
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = -1;
};

/// Runs a program to completion; returns its exit status and fills stdout/stderr.
inline int run(const std::vector<std::string>& args, const std::string& log_prefix,
               std::string* out = nullptr, std::string* err = nullptr,
               std::chrono::seconds timeout = std::chrono::seconds(60)) {
  Child c(args, log_prefix);
  if (!c.started()) return -1;
  const int status = c.wait(timeout);
  if (out) *out = c.out();
  if (err) *err = c.err();
  return status;
}

}  // namespace cvslam::test
