#include "crowdrecon/common/error.hpp"

#include <cmath>
#include <cstdio>

namespace crowdrecon {

std::string FormatNumber(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::string FormatFixed(double value, int decimals) {
  const int n = std::snprintf(nullptr, 0, "%.*f", decimals, value);
  std::string text(static_cast<std::size_t>(n > 0 ? n : 0), '\0');
  std::snprintf(text.data(), text.size() + 1, "%.*f", decimals, value);
  return text;
}

std::string ShortText(std::string_view text, std::size_t max_chars) {
  if (text.size() <= max_chars) return std::string(text);
  std::size_t cut = max_chars > 3 ? max_chars - 3 : 0;
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // UTF-8 continuation byte
  return std::string(text.substr(0, cut)) + "...";
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds)) return "?";
  char buffer[32];
  const long total = std::lround(seconds);
  if (total >= 3600) std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", total / 3600, (total / 60) % 60);
  else if (total >= 60) std::snprintf(buffer, sizeof buffer, "%ldm%02lds", total / 60, total % 60);
  else std::snprintf(buffer, sizeof buffer, "%lds", total);
  return buffer;
}

}  // namespace crowdrecon
