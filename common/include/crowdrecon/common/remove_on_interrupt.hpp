// Partial files that do not outlive Ctrl-C. A writer that keeps its output
// under a hidden partial name until it is complete (PartialPath) holds a
// RemoveOnInterrupt for that name: if SIGINT or SIGTERM ends the program
// meanwhile, the file is removed first, and the signal then ends the program
// as it would have (exit 130 / 143). Where the program has handlers of its
// own for those signals (simulate's checkpointing stop), they are left in
// place and stay in charge. SIGKILL cannot be caught: what it leaves, the
// next writer of the same output removes (RemoveStalePartialsOf).
// A folder may be held too (StagedFolder's): it is removed after the files,
// if they were all it held.
#pragma once

#include <filesystem>

namespace crowdrecon {

class RemoveOnInterrupt {
 public:
  explicit RemoveOnInterrupt(const std::filesystem::path& file);
  ~RemoveOnInterrupt();
  RemoveOnInterrupt(const RemoveOnInterrupt&) = delete;
  RemoveOnInterrupt& operator=(const RemoveOnInterrupt&) = delete;

 private:
  int slot_ = -1;  // -1: not registered (no free slot, or the program handles the signals itself)
};

}  // namespace crowdrecon
