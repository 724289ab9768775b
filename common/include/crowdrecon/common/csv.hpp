// CSV as RFC 4180 writes and reads it, for every CSV the tools write and
// read back: a field holding a comma, a double quote or a line break is
// quoted, with its quotes doubled, and read back the same (issue 40: a
// region named "a, b" gave a CSV that the tools then refused).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace crowdrecon {

// `value` as one CSV field: unchanged, or quoted where it must be.
std::string CsvField(std::string_view value);

struct CsvRecord {
  std::size_t line = 0;  // the line it begins on (1-based), for messages
  std::vector<std::string> fields;
};

// Every record of `text` (LF or CRLF line ends; a quoted field may hold
// commas, doubled quotes and line breaks). Empty lines are skipped. Throws
// InputError naming `origin` and the line of a quoted field left open or of
// a quote inside an unquoted field.
std::vector<CsvRecord> ParseCsv(std::string_view text, const std::string& origin);

}  // namespace crowdrecon
