// Reading picture files (venue plans and body outlines) with checks OpenCV
// does not make, or makes too late:
//   * a folder or a missing file is named as such;
//   * a file cut short is refused: OpenCV decodes a JPEG that stops short with
//     only a warning from libjpeg, the missing rows grey, so a plan or an
//     outline cut short by an interrupted copy would be traced as if whole;
//   * a picture above kMaxImagePixels (input_limits.hpp) is refused from its
//     header, before anything is decoded (PNG, JPEG, BMP, netpbm; other formats
//     after decoding);
//   * OpenCV's own refusals (its pixel limit, a corrupt stream) become
//     InputErrors naming the file.
#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "crowdrecon/common/input_file.hpp"

namespace crowdrecon::geometry::detail {

// Throws InputError (naming the file) if a PNG or JPEG file is cut short:
// a PNG without its IEND chunk, a JPEG whose last scan (SOS marker) is not
// followed by its end-of-image marker, or if the header gives a picture of
// more than kMaxImagePixels. Other formats are left to the decoder.
void CheckImageFile(const std::filesystem::path& file);

// CheckInputFile, CheckImageFile, then cv::imread(file, flags). Returns an
// empty matrix if OpenCV cannot decode the file (the caller says what it
// expected); throws InputError for the refusals above.
cv::Mat ReadImage(const std::filesystem::path& file, int flags);

}  // namespace crowdrecon::geometry::detail
