// Parsing JSON text into a document with the limits and checks of
// crowdrecon's readers (internal to common; JsonDocument uses it).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace crowdrecon::detail {

// Objects and arrays nested deeper than this are refused at parse time (the
// deepest shipped input nests 6 levels); it keeps every later walk over the
// document, printing included, far from the stack's end.
inline constexpr std::size_t kMaxJsonDepth = 100;

// Parses `text`; every problem is an InputError "ORIGIN:LINE:COLUMN: ...":
// syntax errors, numbers beyond the range of a double (1e400), nesting deeper
// than kMaxJsonDepth, and a key given twice in one object (both lines, the
// JSON path and both values are named; JSON leaves duplicates undefined and
// letting the last one win silently hides typos).
nlohmann::json ParseJsonText(std::string_view text, const std::string& origin);

// RFC 6901 escaping of one reference token of a JSON path.
std::string EscapeToken(std::string_view key);

// "file:line:column" of byte `offset` of `text`.
std::string TextPosition(std::string_view text, std::size_t offset, const std::string& origin);

// A bounded rendering of `value` for messages: at most about `max_chars`
// characters, safe on values of any size and depth (no recursion past a few
// levels).
std::string SketchJson(const nlohmann::json& value, std::size_t max_chars = 60);

}  // namespace crowdrecon::detail
