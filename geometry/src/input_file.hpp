// The files a user names for the geometry readers (pictures, WKT, DXF, CSV
// point lists): a missing file and a folder are told apart from a file that
// cannot be parsed, so that no reader reports a folder as an empty file.
#pragma once

#include <filesystem>
#include <string>

namespace crowdrecon::geometry::detail {

// Throws InputError unless `file` can be opened as a file: "FILE: is a
// directory; expected a WHAT", "FILE: cannot open WHAT (it does not exist)".
void CheckInputFile(const std::filesystem::path& file, const std::string& what);

}  // namespace crowdrecon::geometry::detail
