// Reading the files a user names (scenarios, venues, bodies, outlines, WKT,
// sweeps, CSV extracts): one place that tells a missing file, a directory and a
// read failure apart, so that no reader reports a folder as an empty file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace crowdrecon {

// Throws InputError unless `file` is something that can be opened and read as a
// file: "FILE: is a directory; expected a WHAT" or "FILE: cannot open WHAT for
// reading (REASON)". `what` names the kind of file ("scenario file").
void CheckInputFile(const std::filesystem::path& file, std::string_view what);

// The whole content of `file`, after CheckInputFile; a failing read is an
// InputError naming the file too.
std::string ReadInputFile(const std::filesystem::path& file, std::string_view what);

}  // namespace crowdrecon
