// Outlines (geometry::ReadOutline, which chooses the reader by extension):
// the extension is chosen from the content, so that one corpus holds all
// three kinds: PNG signature -> image, '{' or '[' first -> JSON point list,
// anything else -> CSV point list.
#include <string_view>

#include "crowdrecon/geometry/outline.hpp"
#include "fuzz_harness.hpp"

namespace {

std::string_view ExtensionOf(std::string_view text) {
  if (text.substr(0, 4) == "\x89PNG") return "png";
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && (text[first] == '{' || text[first] == '[')) return "json";
  return "csv";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace crowdrecon;
  const auto file = fuzz::WriteScratchFile(data, size, ExtensionOf(fuzz::Text(data, size)));
  return fuzz::Parse([&] { (void)geometry::ReadOutline(file); });
}
