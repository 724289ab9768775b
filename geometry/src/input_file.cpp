#include "input_file.hpp"

#include <fstream>
#include <system_error>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::geometry::detail {

void CheckInputFile(const std::filesystem::path& file, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file.string() + ": is a directory; expected a " + what);
  if (!std::filesystem::exists(file, ec))
    throw InputError(file.string() + ": cannot open " + what + " (it does not exist)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open " + what + " for reading");
}

}  // namespace crowdrecon::geometry::detail
