#pragma once
// A project binary as a child process running beside a test, its stdout and stderr in a file;
// stopped with SIGTERM when the test is done with it (or at the end of the scope).

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <csignal>
#include <string>
#include <vector>

extern char** environ;  // NOLINT(readability-redundant-declaration): <unistd.h> declares it only under _GNU_SOURCE

namespace rpem::test {

class ChildProcess {
 public:
  /// Starts `argv[0]` with `argv`; `pid()` is -1 if it could not be started.
  ChildProcess(std::vector<std::string> argv, const std::string& log) : argv_(std::move(argv)) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> args;
    for (auto& a : argv_) args.push_back(a.data());
    args.push_back(nullptr);
    if (posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() {
    if (pid_ > 0) stop();
  }
  pid_t pid() const { return pid_; }
  void signal(int sig) const { ::kill(pid_, sig); }
  /// SIGTERM, then its exit code (-1 if it did not exit by itself).
  int stop() {
    ::kill(pid_, SIGTERM);
    return wait();
  }
  /// Waits for it to end; its exit code (-1 if killed by a signal).
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  std::vector<std::string> argv_;
  pid_t pid_ = -1;
};

}  // namespace rpem::test
