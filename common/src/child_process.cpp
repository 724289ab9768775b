#include "crowdrecon/common/child_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <thread>

extern char** environ;

namespace crowdrecon {

namespace {

volatile std::sig_atomic_t g_caught = 0;
void OnSignal(int signal) { g_caught = signal; }

// SIGINT and SIGTERM caught for as long as it lives; the previous handlers after.
class CatchInterruptions {
 public:
  CatchInterruptions() {
    g_caught = 0;
    struct sigaction on {};
    on.sa_handler = OnSignal;
    sigemptyset(&on.sa_mask);
    sigaction(SIGINT, &on, &int_);
    sigaction(SIGTERM, &on, &term_);
  }
  ~CatchInterruptions() {
    sigaction(SIGINT, &int_, nullptr);
    sigaction(SIGTERM, &term_, nullptr);
  }
  CatchInterruptions(const CatchInterruptions&) = delete;
  CatchInterruptions& operator=(const CatchInterruptions&) = delete;

 private:
  struct sigaction int_ {}, term_ {};
};

std::string Described(int status, ChildResult* r) {
  if (WIFEXITED(status)) {
    r->exit_code = WEXITSTATUS(status);
    return "exit status " + std::to_string(r->exit_code);
  }
  if (WIFSIGNALED(status)) {
    r->signal = WTERMSIG(status);
    return "killed by signal " + std::to_string(r->signal) + " (" + strsignal(r->signal) + ")";
  }
  return "ended with wait status " + std::to_string(status);
}

// Ends the child's process group: SIGTERM, up to a second's grace, then
// SIGKILL; reaps the child.
int EndGroup(pid_t pid) {
  kill(-pid, SIGTERM);
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(-pid, SIGKILL);  // whatever of the group outlived the child
  return status;
}

}  // namespace

ChildResult RunChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log, double time_limit_s) {
  ChildResult result;
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setpgroup(&attributes, 0);  // a group of its own: crowdrecon ends it as a whole
  sigset_t defaults, none;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  CatchInterruptions catching;
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, args[0], &files, &attributes, args.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  posix_spawnattr_destroy(&attributes);
  if (spawned != 0) {
    result.problem = std::string("cannot be started: ") + std::strerror(spawned);
    return result;
  }
  result.started = true;
  const auto started = std::chrono::steady_clock::now();
  int status = 0;
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (g_caught != 0 || elapsed_s > time_limit_s) {
      status = EndGroup(pid);
      if (g_caught != 0) {
        const int signal = g_caught;
        throw Interrupted(signal, std::string("interrupted by ") + (signal == SIGINT ? "SIGINT" : "SIGTERM") + " while " +
                                      argv[0] + " ran; it was ended");
      }
      result.timed_out = true;
      result.problem = "did not finish within " + std::to_string(static_cast<int>(time_limit_s)) + " s and was ended";
      return result;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(-pid, SIGKILL);  // helpers left in its group (Chromium's) end with it
  const std::string described = Described(status, &result);
  if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) result.problem = described;
  return result;
}

}  // namespace crowdrecon
