// The command line's run: parse, run the command, and turn what it throws
// into the exit statuses of the README ("Exit status"): one place for
// crowdrecon and the lean crowdrecon-simulate (issue 42).
#include <cstdio>
#include <exception>
#include <new>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "crowdrecon/common/child_process.hpp"  // (Interrupted)
#include "crowdrecon/common/error.hpp"

namespace crowdrecon::cli {
namespace {
std::string command_line;
}
const std::string& CommandLine() { return command_line; }
void SetCommandLine(int argc, char** argv) {
  command_line.clear();
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool plain = !arg.empty() && arg.find_first_of(" \t'\"$`\\") == std::string::npos;
    command_line += (i ? " " : "") + (plain ? arg : "'" + arg + "'");
  }
}

int RunCommandLine(CLI::App& app, int argc, char** argv) {
  SetCommandLine(argc, argv);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a command's own status (130 / 143: interrupted)
  } catch (const CLI::ParseError& e) {
    // --help and --version: 0; a usage error: 2, as any bad input (CLI11's
    // own codes, 105-115, said nothing more and differed by kind).
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "crowdrecon: error: %s\n", e.what());
    return 2;
  } catch (const Interrupted& e) {
    // The file being written when it came is removed as the exception passes.
    std::fprintf(stderr, "crowdrecon: %s\n", e.what());
    return 128 + e.signal();
  } catch (const SetupError& e) {
    std::fprintf(stderr, "crowdrecon: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // The limits on people, runs, nesting and image size should keep every
    // input within memory; if one still is not, say so rather than "internal error".
    std::fprintf(stderr,
                 "crowdrecon: error: out of memory while running \"%s\"; the input is larger than this machine's "
                 "memory allows: check its scale and counts (people, runs, pixels), or close other programs\n",
                 app.get_subcommands().empty() ? "crowdrecon" : app.get_subcommands().front()->get_name().c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crowdrecon: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}

}  // namespace crowdrecon::cli
