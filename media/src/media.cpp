// media.hpp's functions: each forwards to the codecs module, which is loaded
// the first time one is called (media/CMakeLists.txt).
#include "crowdrecon/media/media.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::media {
namespace {

// The module built beside this library (CMake gives its path), or the one
// named by CROWDRECON_MEDIA_CODECS (for a program moved away from its build).
const detail::Codecs& LoadedCodecs() {
  static const detail::Codecs* const codecs = [] {
    const char* chosen = std::getenv("CROWDRECON_MEDIA_CODECS");
    const std::string path = chosen && *chosen ? chosen : CROWDRECON_MEDIA_CODECS_PATH;
    const auto fail = [&](const std::string& why) -> const detail::Codecs* {
      throw SetupError("cannot load the picture and video codecs (" + path + "): " + why +
                               "; rebuild crowdrecon, or set CROWDRECON_MEDIA_CODECS to the path of "
                               "libcrowdrecon_media_codecs.so");
    };
    void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) return fail(dlerror());
    using Entry = const detail::Codecs* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(module, "crowdrecon_media_codecs_v1"));
    if (!entry) return fail("no entry point crowdrecon_media_codecs_v1");
    const detail::Codecs* loaded = entry();
    if (!loaded || loaded->version != detail::kCodecsVersion) return fail("a module of another version");
    return loaded;  // the module stays loaded until the program ends
  }();
  return *codecs;
}

}  // namespace

cv::Mat ReadImage(const std::string& path, int flags) { return LoadedCodecs().read_image(path, flags); }
bool WriteImage(const std::string& path, const cv::Mat& image) { return LoadedCodecs().write_image(path, image); }
std::unique_ptr<VideoReader> MakeVideoReader() { return std::unique_ptr<VideoReader>(LoadedCodecs().new_reader()); }
std::unique_ptr<VideoWriter> MakeVideoWriter() { return std::unique_ptr<VideoWriter>(LoadedCodecs().new_writer()); }

std::string IncompleteVideo(const std::string& path) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return "cannot be read back: " + ec.message();
  std::ifstream in(path, std::ios::binary);
  const auto read = [&in](std::uint64_t at, std::size_t n) {
    std::string bytes(n, '\0');
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));
    in.read(bytes.data(), static_cast<std::streamsize>(n));
    bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
    return bytes;
  };
  const auto number = [](const std::string& b, std::size_t from, std::size_t n, bool big_endian) {
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < n; ++k)
      v |= std::uint64_t(static_cast<unsigned char>(b[from + (big_endian ? n - 1 - k : k)])) << (8 * k);
    return v;
  };
  const std::string head = read(0, 12);
  if (head.size() < 12) return "holds only " + std::to_string(size) + " bytes";
  const bool avi = head.compare(0, 4, "RIFF") == 0;
  // AVI (OpenDML too): RIFF chunks one after another, each "RIFF" + its
  // size (little-endian) + that many bytes, padded to even. MP4: boxes, each
  // its size (big-endian; 1: a 64-bit size follows; 0: to the end) + type.
  std::uint64_t at = 0;
  while (at < size) {
    const std::string h = read(at, 16);
    if (h.size() < 8) break;
    std::uint64_t length;
    if (avi) {
      if (h.compare(0, 4, "RIFF") != 0) return "holds something other than a RIFF chunk at byte " + std::to_string(at);
      length = 8 + number(h, 4, 4, false);
      length += length % 2;
    } else {
      length = number(h, 0, 4, true);
      if (length == 1) {
        if (h.size() < 16) break;
        length = number(h, 8, 8, true);
      } else if (length == 0) {
        length = size - at;
      }
      if (length < 8) return "holds a damaged box at byte " + std::to_string(at);
    }
    at += length;
  }
  if (at != size)
    return "ends at " + std::to_string(size) + " bytes where its " + (avi ? "RIFF chunks say " : "boxes say ") +
           std::to_string(at);
  return "";
}

void RequireCompleteVideo(const std::string& path, const std::string& video) {
  if (const std::string wrong = IncompleteVideo(path); !wrong.empty())
    throw InputError(video + ": the video could not be written completely (disk full?): it " + wrong);
}

}  // namespace crowdrecon::media
