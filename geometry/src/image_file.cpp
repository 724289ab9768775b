#include "image_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/input_limits.hpp"
#include "crowdrecon/media/media.hpp"

namespace crowdrecon::geometry::detail {

namespace {

using Bytes = std::vector<std::uint8_t>;

struct Size {
  std::uint64_t width = 0, height = 0;
};

std::uint32_t BigEndian(const Bytes& b, std::size_t at, int count) {
  std::uint32_t v = 0;
  for (int k = 0; k < count; ++k) v = (v << 8) | b[at + static_cast<std::size_t>(k)];
  return v;
}

std::uint32_t LittleEndian(const Bytes& b, std::size_t at, int count) {
  std::uint32_t v = 0;
  for (int k = count - 1; k >= 0; --k) v = (v << 8) | b[at + static_cast<std::size_t>(k)];
  return v;
}

constexpr std::array<std::uint8_t, 8> kPng{0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};

bool IsPng(const Bytes& b) { return b.size() >= kPng.size() && std::equal(kPng.begin(), kPng.end(), b.begin()); }
bool IsJpeg(const Bytes& b) { return b.size() >= 2 && b[0] == 0xFF && b[1] == 0xD8; }

// The picture's size from its header, for the formats whose header is simple.
std::optional<Size> HeaderSize(const Bytes& b) {
  if (IsPng(b) && b.size() >= 24 && std::equal(b.begin() + 12, b.begin() + 16, "IHDR"))
    return Size{BigEndian(b, 16, 4), BigEndian(b, 20, 4)};
  if (IsJpeg(b)) {
    // Marker segments up to the first start-of-frame (SOF0..SOF15 except the
    // DHT, JPG and DAC markers C4, C8, CC): precision, height, width.
    std::size_t at = 2;
    while (at + 9 < b.size() && b[at] == 0xFF) {
      const std::uint8_t marker = b[at + 1];
      if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
        return Size{BigEndian(b, at + 7, 2), BigEndian(b, at + 5, 2)};
      at += 2 + BigEndian(b, at + 2, 2);
    }
    return std::nullopt;
  }
  if (b.size() >= 26 && b[0] == 'B' && b[1] == 'M') {
    const auto height = static_cast<std::int32_t>(LittleEndian(b, 22, 4));
    return Size{LittleEndian(b, 18, 4), static_cast<std::uint64_t>(height < 0 ? -std::int64_t{height} : height)};
  }
  if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') {
    // Netpbm: "P5 WIDTH HEIGHT ...", with '#' comments between the fields.
    std::size_t at = 2;
    std::array<std::uint64_t, 2> field{};
    for (std::uint64_t& value : field) {
      while (at < b.size() && (std::isspace(b[at]) || b[at] == '#')) {
        if (b[at] == '#')
          while (at < b.size() && b[at] != '\n') ++at;
        else
          ++at;
      }
      if (at >= b.size() || !std::isdigit(b[at])) return std::nullopt;
      while (at < b.size() && std::isdigit(b[at]) && value < (std::uint64_t{1} << 40))
        value = value * 10 + static_cast<std::uint64_t>(b[at++] - '0');
    }
    return Size{field[0], field[1]};
  }
  return std::nullopt;
}

[[noreturn]] void TooLarge(const std::filesystem::path& file, double width, double height) {
  throw InputError(file.string() + ": the picture is " + FormatNumber(width) + " x " + FormatNumber(height) +
                   " pixels (" + FormatNumber(width * height / 1e6) + " megapixels); at most " +
                   FormatNumber(kMaxImagePixels / 1e6) +
                   " megapixels are accepted: check the resolution (a body outline needs about 1000 pixels "
                   "across, a floor plan about 50 pixels per metre)");
}

void CheckComplete(const std::filesystem::path& file, const Bytes& bytes) {
  const auto cut_short = [&](const std::string& what) {
    throw InputError(file.string() + ": " + what + " (" + std::to_string(bytes.size()) +
                     " bytes): the file looks cut short; expected a complete picture");
  };
  // OpenCV hands a file with "DICM" at byte 128 to GDCM (DICOM), whose
  // assertions abort the whole program on a damaged one (found by fuzzing,
  // docs/fuzzing.md); a floor plan or body outline is never a DICOM file.
  if (bytes.size() >= 132 && std::string(bytes.begin() + 128, bytes.begin() + 132) == "DICM")
    throw InputError(file.string() + ": a DICOM (medical) image (\"DICM\" at byte 128); expected a picture (PNG, JPEG, BMP, TIFF, ...)");
  if (IsPng(bytes)) {
    // Walk the chunks (length, type, data, CRC) to IEND.
    std::size_t at = kPng.size();
    while (at + 8 <= bytes.size()) {
      const std::uint32_t length = BigEndian(bytes, at, 4);
      const std::string type(bytes.begin() + static_cast<std::ptrdiff_t>(at + 4),
                             bytes.begin() + static_cast<std::ptrdiff_t>(at + 8));
      if (std::uint64_t{at} + 12 + length > bytes.size()) break;
      if (type == "IEND") return;
      at += 12 + length;
    }
    cut_short("PNG without its closing IEND chunk");
  }
  if (IsJpeg(bytes)) {
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

}  // namespace

void CheckImageFile(const std::filesystem::path& file) {
  const std::string data = ReadInputFile(file, "picture file");
  const Bytes bytes(data.begin(), data.end());
  if (const auto size = HeaderSize(bytes)) {
    const double width = static_cast<double>(size->width), height = static_cast<double>(size->height);
    if (width * height > kMaxImagePixels) TooLarge(file, width, height);
  }
  CheckComplete(file, bytes);
}

cv::Mat ReadImage(const std::filesystem::path& file, int flags) {
  CheckImageFile(file);
  cv::Mat image;
  try {
    image = media::ReadImage(file.string(), flags);
  } catch (const cv::Exception& e) {
    // OpenCV's own pixel limit (OPENCV_IO_MAX_IMAGE_PIXELS, 2^30 by default)
    // and decoder failures of formats whose header is not read above.
    throw InputError(file.string() + ": OpenCV cannot decode the picture (" + e.err +
                     "); expected a picture of at most " + FormatNumber(kMaxImagePixels / 1e6) +
                     " megapixels in PNG, JPEG, BMP or TIFF");
  }
  if (!image.empty() && static_cast<double>(image.total()) > kMaxImagePixels)
    TooLarge(file, image.cols, image.rows);
  return image;
}

}  // namespace crowdrecon::geometry::detail
