#include "image_file.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry::detail {

void CheckImageFileComplete(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open image file for reading");
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto cut_short = [&](const std::string& what) {
    throw InputError(file.string() + ": " + what + " (" + std::to_string(bytes.size()) +
                     " bytes): the file looks cut short; expected a complete picture");
  };
  // OpenCV hands a file with "DICM" at byte 128 to GDCM (DICOM), whose
  // assertions abort the whole program on a damaged one (found by fuzzing,
  // docs/fuzzing.md); a floor plan or body outline is never a DICOM file.
  if (bytes.size() >= 132 && std::string(bytes.begin() + 128, bytes.begin() + 132) == "DICM")
    throw InputError(file.string() + ": a DICOM (medical) image (\"DICM\" at byte 128); expected a picture (PNG, JPEG, BMP, TIFF, ...)");
  constexpr std::array<std::uint8_t, 8> kPng{0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  if (bytes.size() >= kPng.size() && std::equal(kPng.begin(), kPng.end(), bytes.begin())) {
    // Walk the chunks (length, type, data, CRC) to IEND.
    std::size_t at = kPng.size();
    while (at + 8 <= bytes.size()) {
      const std::uint32_t length = (std::uint32_t{bytes[at]} << 24) | (std::uint32_t{bytes[at + 1]} << 16) |
                                   (std::uint32_t{bytes[at + 2]} << 8) | bytes[at + 3];
      const std::string type(bytes.begin() + static_cast<std::ptrdiff_t>(at + 4),
                             bytes.begin() + static_cast<std::ptrdiff_t>(at + 8));
      if (std::uint64_t{at} + 12 + length > bytes.size()) break;
      if (type == "IEND") return;
      at += 12 + length;
    }
    cut_short("PNG without its closing IEND chunk");
  }
  if (bytes.size() >= 2 && bytes[0] == 0xFF && bytes[1] == 0xD8) {
    // Inside a scan's entropy-coded data a 0xFF byte is always followed by
    // 0x00 or a restart marker, so the last SOS (FF DA) and the EOI (FF D9)
    // that must follow it cannot be mistaken. (Bytes after the EOI, which
    // some cameras append, are allowed.)
    std::size_t last_scan = bytes.size();
    for (std::size_t k = 2; k + 1 < bytes.size(); ++k)
      if (bytes[k] == 0xFF && bytes[k + 1] == 0xDA) last_scan = k;
    if (last_scan == bytes.size()) cut_short("JPEG without image data (no start-of-scan marker)");
    for (std::size_t k = last_scan + 2; k + 1 < bytes.size(); ++k)
      if (bytes[k] == 0xFF && bytes[k + 1] == 0xD9) return;
    cut_short("JPEG whose image data stops without the end-of-image marker");
  }
}

}  // namespace crowdrecon::geometry::detail
