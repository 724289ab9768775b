// Running another program (Chromium, for report.pdf) so that Ctrl-C and
// SIGTERM stop the command promptly: the child runs in a process group of
// its own with its output in a log file; while it runs, SIGINT and SIGTERM
// are caught, and the child's whole group is ended (SIGTERM, then SIGKILL
// after a second) before Interrupted is thrown, so that nothing of
// it keeps running; a child that outlives its time limit is ended the same
// way. If crowdrecon itself is killed (even by SIGKILL), the child gets
// SIGKILL too (Linux's parent-death signal). No shell is involved: the
// arguments reach the program as given.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace crowdrecon {

// SIGINT or SIGTERM arrived while crowdrecon waited: the command stops,
// removes what it had begun to write, and exits 128 + signal (130, 143).
class Interrupted : public std::runtime_error {
 public:
  Interrupted(int signal, const std::string& what) : std::runtime_error(what), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

struct ChildResult {
  bool started = false;   // false: the program could not be started (`problem` says why)
  bool timed_out = false; // ended by crowdrecon after the time limit
  int exit_code = -1;     // the program's exit status when it exited
  int signal = 0;         // the signal that ended it, if one did
  std::string problem;    // in words, when it did not exit with 0: "exit status 3", "killed by signal 9 (Killed)", ...
};

// Runs argv[0] (a path) with argv, stdin from /dev/null, stdout and stderr
// into `log` (created or emptied). Waits at most time_limit_s. Throws
// Interrupted on SIGINT/SIGTERM after ending the child's group.
ChildResult RunChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log, double time_limit_s);

}  // namespace crowdrecon
