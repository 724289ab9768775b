// RemoveOnInterrupt (common/remove_on_interrupt.hpp): a partial file held by
// one goes when SIGINT or SIGTERM ends the program, and the signal still
// ends it; where the program handles the signals itself, nothing changes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>

#include "crowdrecon/common/remove_on_interrupt.hpp"

namespace crowdrecon {
namespace {

// Runs `body` in a child process; returns its wait status.
template <typename F>
int InChild(F body) {
  const pid_t pid = fork();
  if (pid == 0) {
    body();
    _exit(0);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

extern "C" void Ignore(int) {}

TEST(RemoveOnInterrupt, APartialFileGoesWithCtrlCAndTheSignalStillEndsTheProgram) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "crowdrecon-remove-on-interrupt";
  std::filesystem::create_directories(dir);
  for (int signal : {SIGINT, SIGTERM}) {
    const std::filesystem::path partial = dir / ".out.partial-1.png", kept = dir / "kept.png";
    std::ofstream(partial) << "half a picture";
    std::ofstream(kept) << "another file";
    const int status = InChild([&] {
      RemoveOnInterrupt guard(partial);
      std::raise(signal);
    });
    ASSERT_TRUE(WIFSIGNALED(status)) << "the signal ends the program as before";
    EXPECT_EQ(WTERMSIG(status), signal);
    EXPECT_FALSE(std::filesystem::exists(partial)) << strsignal(signal);
    EXPECT_TRUE(std::filesystem::exists(kept));
  }
  // Released, it removes nothing; with the program's own handler, it stays out.
  const std::filesystem::path released = dir / ".released.partial-1.png", handled = dir / ".handled.partial-1.png";
  std::ofstream(released) << "x";
  std::ofstream(handled) << "x";
  const int status = InChild([&] {
    { RemoveOnInterrupt guard(released); }
    std::signal(SIGINT, Ignore);
    RemoveOnInterrupt guard(handled);
    std::raise(SIGINT);  // handled by the program: no removal, no exit
  });
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_TRUE(std::filesystem::exists(released));
  EXPECT_TRUE(std::filesystem::exists(handled));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace crowdrecon
