// WKT walkable areas (POLYGON / MULTIPOLYGON, as written by JuPedSim, PedPy
// and shapely). A small recursive-descent parser of our own rather than
// CGAL's WKT reader, because a user needs the line and column of a syntax error,
// which CGAL's reader does not report.
#include <cctype>
#include <cmath>
#include <charconv>
#include <fstream>
#include <sstream>
#include <string>

#include "crowdrecon/common/error.hpp"
#include "crowdrecon/geometry/venue.hpp"
#include "crowdrecon/common/input_file.hpp"
#include "venue_internal.hpp"

namespace crowdrecon::geometry {

namespace {

class WktParser {
 public:
  WktParser(std::string_view text, std::string origin, double scale)
      : text_(text), origin_(std::move(origin)), scale_(scale) {}

  std::vector<internal::ImportedRegion> Parse() {
    SkipSpace();
    const std::string keyword = Word();
    if (keyword.empty()) Fail("expected POLYGON or MULTIPOLYGON");
    std::string upper = keyword;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (upper != "POLYGON" && upper != "MULTIPOLYGON")
      Fail("unsupported geometry type \"" + keyword + "\"; expected POLYGON or MULTIPOLYGON", keyword.size());
    SkipDimensionTag();
    std::vector<internal::ImportedRegion> regions;
    if (!TryEmpty()) {
      if (upper == "POLYGON") {
        regions.push_back(PolygonText());
      } else {
        Expect('(');
        do regions.push_back(PolygonText());
        while (TryChar(','));
        Expect(')');
      }
    }
    SkipSpace();
    if (pos_ < text_.size()) Fail("unexpected text after the end of the geometry");
    return regions;
  }

 private:
  // "origin:line:column: message" for the current position.
  [[noreturn]] void Fail(const std::string& message, std::size_t back = 0) const {
    const std::size_t at = pos_ >= back ? pos_ - back : 0;
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < at && i < text_.size(); ++i) {
      if (text_[i] == '\n') { ++line; column = 1; } else { ++column; }
    }
    throw InputError(origin_ + ":" + std::to_string(line) + ":" + std::to_string(column) +
                     ": invalid WKT: " + message);
  }

  std::string Found() const {
    if (pos_ >= text_.size()) return "end of input";
    // Built piecewise: GCC 12 at -O3 raises a false -Wrestrict on
    // "'" + std::string(1, c) + "'".
    std::string quoted = "'";
    quoted += text_[pos_];
    quoted += '\'';
    return quoted;
  }

  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }

  std::string Word() {
    SkipSpace();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && std::isalpha(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return std::string(text_.substr(start, pos_ - start));
  }

  // "POLYGON Z (...)": accepted, the extra ordinates are ignored.
  void SkipDimensionTag() {
    const std::size_t save = pos_;
    std::string w = Word();
    for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (w != "Z" && w != "M" && w != "ZM") pos_ = save;
  }

  bool TryEmpty() {
    const std::size_t save = pos_;
    std::string w = Word();
    for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (w == "EMPTY") return true;
    pos_ = save;
    return false;
  }

  bool TryChar(char c) {
    SkipSpace();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }

  void Expect(char c) {
    if (!TryChar(c)) Fail(std::string("expected '") + c + "' but found " + Found());
  }

  double Number() {
    SkipSpace();
    const char* begin = text_.data() + pos_;
    const char* end = text_.data() + text_.size();
    // from_chars does not accept a leading '+'; WKT writers never emit one.
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(begin, end, value);
    if (ptr == begin) Fail("expected a number but found " + Found());
    // from_chars reads "nan" and "inf" too, and gives up on 1e400.
    const std::string_view token(begin, static_cast<std::size_t>(ptr - begin));
    const std::string shown(token.substr(0, 40));
    if (ec == std::errc::result_out_of_range)
      Fail("the number " + shown + " is out of range; expected a finite coordinate");
    if (ec != std::errc()) Fail("expected a number but found " + Found());
    if (!std::isfinite(value)) Fail("the number " + shown + " is not finite; expected a finite coordinate");
    pos_ += token.size();
    return value;
  }

  Vec2 PointText() {
    const double x = Number();
    const double y = Number();
    // Optional Z and M ordinates.
    for (int extra = 0; extra < 2; ++extra) {
      SkipSpace();
      if (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != ')') Number();
    }
    return {x * scale_, y * scale_};
  }

  Ring RingText() {
    SkipSpace();
    const std::size_t ring_start = pos_;
    Expect('(');
    Ring ring;
    do ring.push_back(PointText());
    while (TryChar(','));
    Expect(')');
    // Report ring errors at the ring's opening parenthesis.
    if (ring.size() < 4) {
      pos_ = ring_start;
      Fail("ring has " + std::to_string(ring.size()) + " points; expected at least 4 (a closed triangle)");
    }
    if (ring.front() != ring.back()) {
      pos_ = ring_start;
      Fail("ring is not closed (first point differs from last); expected the first point repeated at the end");
    }
    ring.pop_back();
    return ring;
  }

  internal::ImportedRegion PolygonText() {
    Expect('(');
    internal::ImportedRegion region;
    region.outer = RingText();
    while (TryChar(',')) region.holes.push_back(RingText());
    Expect(')');
    return region;
  }

  std::string_view text_;
  std::string origin_;
  double scale_;
  std::size_t pos_ = 0;
};

std::string StemOf(const std::string& origin) { return std::filesystem::path(origin).stem().string(); }

}  // namespace

Venue ParseWkt(std::string_view text, const std::string& origin, const ImportOptions& options) {
  const double scale = options.scale_m_per_unit > 0.0 ? options.scale_m_per_unit : 1.0;
  std::vector<internal::ImportedRegion> regions = WktParser(text, origin, scale).Parse();
  if (regions.empty())
    throw GeometryError(origin + ": the WKT geometry is EMPTY; expected a walkable area with at least one polygon");
  return internal::VenueFromRegions(std::move(regions), options.name.empty() ? StemOf(origin) : options.name,
                                    "imported from " + std::filesystem::path(origin).filename().string() +
                                        " (WKT)",
                                    origin);
}

Venue ImportWkt(const std::filesystem::path& file, const ImportOptions& options) {
  return ParseWkt(ReadInputFile(file, "WKT file"), file.string(), options);
}

}  // namespace crowdrecon::geometry
