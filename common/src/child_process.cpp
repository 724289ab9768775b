#include "crowdrecon/common/child_process.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cerrno>
#include <cstring>
#include <thread>

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
  const std::string log_path = log.string();
  CatchInterruptions catching;
  // A pipe that closes on exec tells a failed exec's errno to the parent.
  int report[2];
  if (pipe2(report, O_CLOEXEC) != 0) {
    result.problem = std::string("cannot be started: ") + std::strerror(errno);
    return result;
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    close(report[0]);
    close(report[1]);
    result.problem = std::string("cannot be started: ") + std::strerror(errno);
    return result;
  }
  if (pid == 0) {
    // The child: only async-signal-safe calls until exec. A group of its
    // own (crowdrecon ends it as a whole); killed if crowdrecon dies, even
    // by SIGKILL (Linux's parent-death signal), so no browser outlives it.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    struct sigaction standard {};
    standard.sa_handler = SIG_DFL;
    sigemptyset(&standard.sa_mask);
    sigaction(SIGINT, &standard, nullptr);
    sigaction(SIGTERM, &standard, nullptr);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || dup2(in, 0) < 0 || dup2(out, 1) < 0 || dup2(out, 2) < 0) {
      const int e = errno;
      (void)!write(report[1], &e, sizeof e);
      _exit(127);
    }
    execv(args[0], args.data());
    const int e = errno;
    (void)!write(report[1], &e, sizeof e);
    _exit(127);
  }
  close(report[1]);
  int exec_errno = 0;
  const ssize_t got = read(report[0], &exec_errno, sizeof exec_errno);
  close(report[0]);
  if (got == static_cast<ssize_t>(sizeof exec_errno)) {
    int ignored = 0;
    waitpid(pid, &ignored, 0);
    result.problem = std::string("cannot be started: ") + std::strerror(exec_errno);
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
