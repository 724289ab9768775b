// The --force flag shared by every command that writes (commands.hpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace crowdrecon::cli {

void AddForceFlag(CLI::App* cmd, bool* force) {
  cmd->add_flag("--force", *force,
                "Replace an existing file, or write into an existing folder, that is not a previous output of this "
                "command (an input is never overwritten and nothing in a folder is deleted)");
}

}  // namespace crowdrecon::cli
