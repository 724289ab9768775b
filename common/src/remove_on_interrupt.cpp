#include "crowdrecon/common/remove_on_interrupt.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <mutex>
#include <string>

namespace crowdrecon {

namespace {

// The files to remove, in fixed buffers the handler reads without locking
// or freeing (a slot's flag is set after its path is written).
constexpr int kSlots = 32;
constexpr std::size_t kPathBytes = 4096;
char g_paths[kSlots][kPathBytes];
std::atomic<bool> g_used[kSlots];
std::mutex g_mutex;  // guards installing and restoring the handlers
int g_registered = 0;
struct sigaction g_previous_int {}, g_previous_term {};

extern "C" void RemoveAndDie(int signal) {
  for (int k = 0; k < kSlots; ++k)
    if (g_used[k].load()) unlink(g_paths[k]);
  // Then the folders, emptied by the first pass (rmdir fails on the rest).
  for (int k = 0; k < kSlots; ++k)
    if (g_used[k].load()) rmdir(g_paths[k]);
  std::signal(signal, SIG_DFL);
  std::raise(signal);
}

bool DefaultDisposition(int signal) {
  struct sigaction current {};
  sigaction(signal, nullptr, &current);
  return current.sa_handler == SIG_DFL || current.sa_handler == RemoveAndDie;
}

}  // namespace

RemoveOnInterrupt::RemoveOnInterrupt(const std::filesystem::path& file) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!DefaultDisposition(SIGINT) || !DefaultDisposition(SIGTERM)) return;  // the program's own handlers
  const std::string path = file.string();
  if (path.size() >= kPathBytes) return;
  for (int k = 0; k < kSlots; ++k) {
    if (g_used[k].load()) continue;
    std::memcpy(g_paths[k], path.c_str(), path.size() + 1);
    g_used[k].store(true);
    slot_ = k;
    break;
  }
  if (slot_ < 0) return;
  if (g_registered++ == 0) {
    struct sigaction remove {};
    remove.sa_handler = RemoveAndDie;
    sigemptyset(&remove.sa_mask);
    sigaction(SIGINT, &remove, &g_previous_int);
    sigaction(SIGTERM, &remove, &g_previous_term);
  }
}

RemoveOnInterrupt::~RemoveOnInterrupt() {
  if (slot_ < 0) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_used[slot_].store(false);
  if (--g_registered == 0) {
    sigaction(SIGINT, &g_previous_int, nullptr);
    sigaction(SIGTERM, &g_previous_term, nullptr);
  }
}

}  // namespace crowdrecon
