// media.hpp's functions: each forwards to the codecs module, which is loaded
// the first time one is called (media/CMakeLists.txt).
#include "crowdrecon/media/media.hpp"

#include <dlfcn.h>

#include <cstdlib>

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

}  // namespace crowdrecon::media
