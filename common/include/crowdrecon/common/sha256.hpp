// SHA-256 (FIPS 180-4) of files and text, for the reproducibility sections
// of reports: another engineer checks the inputs with `sha256sum`.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace crowdrecon {

class Sha256 {
 public:
  Sha256();
  void Update(const void* data, std::size_t bytes);
  // The digest as 64 lower-case hex digits; the object is spent afterwards.
  std::string HexDigest();

 private:
  void Block(const std::uint8_t* block);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  std::uint64_t length_ = 0;
};

std::string Sha256Hex(std::string_view text);
// Throws InputError naming the file if it cannot be read.
std::string Sha256OfFile(const std::filesystem::path& file);

}  // namespace crowdrecon
