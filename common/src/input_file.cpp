#include "crowdrecon/common/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon {

void CheckInputFile(const std::filesystem::path& file, std::string_view what) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  // "a DXF file", "an ANSUR II extract"; a description with its own article
  // ("the test's scenario") as it is.
  const bool has_article = what.rfind("the ", 0) == 0 || what.rfind("a ", 0) == 0 || what.rfind("an ", 0) == 0;
  const std::string expected =
      (has_article ? std::string()
                   : std::string(std::string_view("AEIOUaeiou").find(what.front()) != std::string_view::npos ? "an " : "a ")) +
      std::string(what);
  if (std::filesystem::is_directory(status)) throw InputError(file.string() + ": is a directory; expected " + expected);
  // A device (/dev/zero, a terminal) or a socket never ends or never answers;
  // a pipe (a shell's <(...)) ends, and is read like a file.
  if (std::filesystem::is_character_file(status) || std::filesystem::is_block_file(status) ||
      std::filesystem::is_socket(status))
    throw InputError(file.string() + ": is a device or socket, not a file; expected " + expected);
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const int error = errno;
    throw InputError(file.string() + ": cannot open " + std::string(what) + " for reading (" +
                     std::strerror(error) + ")");
  }
}

std::string ReadInputFile(const std::filesystem::path& file, std::string_view what) {
  CheckInputFile(file, what);
  std::ifstream in(file, std::ios::binary);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw InputError(file.string() + ": cannot read " + std::string(what) + " (read error)");
  return text;
}

}  // namespace crowdrecon
