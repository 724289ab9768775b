// Checks on picture files before OpenCV decodes them (venue plans and body
// outlines). OpenCV decodes a JPEG that stops short with only a warning from
// libjpeg, the missing rows grey: a plan or an outline cut short by an
// interrupted copy would be traced as if it were whole.
#pragma once

#include <filesystem>

namespace crowdrecon::geometry::detail {

// Throws InputError (naming the file) if a PNG or JPEG file is cut short:
// a PNG without its IEND chunk, a JPEG whose last scan (SOS marker) is not
// followed by its end-of-image marker. Other formats are left to the decoder.
void CheckImageFileComplete(const std::filesystem::path& file);

}  // namespace crowdrecon::geometry::detail
