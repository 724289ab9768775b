// What every fuzz harness shares (docs/fuzzing.md). A harness defines
// LLVMFuzzerTestOneInput, hands the bytes to one of the project's real
// parsers and calls it through Parse(): an InputError (GeometryError
// included) is the parser rejecting bad input, as it should; anything else
// (another exception, a signal, a sanitizer report) escapes and is a crash.
//
// Built with clang and -fsanitize=fuzzer the harness is a libFuzzer binary;
// built with GCC it links with replay_main.cpp, which runs it over corpus
// folders (the ctest tests fuzz.replay.*).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::fuzz {

// The input as text (for the parsers that read from memory).
inline std::string Text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// The project's source tree, where relative paths of fuzzed scenarios and
// sweeps resolve (venues/, tests/data/).
inline std::filesystem::path SourceDir() { return CROWDRECON_SOURCE_DIR; }

// This process's scratch folder (removed at exit): libFuzzer runs one input
// after another in one process, so one folder and one file per extension do.
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path d =
        std::filesystem::temp_directory_path() / ("crowdrecon-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  static const bool cleanup_registered = [] {
    return std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(ScratchDir(), ignored);
    }) == 0;
  }();
  (void)cleanup_registered;
  return dir;
}

// Writes the input to the scratch file "input.EXT" (for the parsers that
// take a path; some choose the format by extension) and returns its path.
// Files a previous input left beside it (SQLite's -wal, -shm, -journal) are
// removed first, so that every input is read alone.
inline std::filesystem::path WriteScratchFile(const std::uint8_t* data, std::size_t size, std::string_view ext) {
  const std::filesystem::path file = ScratchDir() / ("input." + std::string(ext));
  for (const char* suffix : {"-wal", "-shm", "-journal"}) {
    std::error_code ignored;
    std::filesystem::remove(file.string() + suffix, ignored);
  }
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out.flush()) std::abort();  // the harness's own failure, not the parser's
  return file;
}

// Runs the parser; an InputError is an expected rejection.
template <class ParseFn>
int Parse(ParseFn&& parse) {
  try {
    parse();
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace crowdrecon::fuzz
