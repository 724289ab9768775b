#include "crowdrecon/common/csv.hpp"

#include "crowdrecon/common/error.hpp"

namespace crowdrecon {

std::string CsvField(std::string_view value) {
  if (value.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(value);
  std::string out = "\"";
  for (char c : value) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::vector<CsvRecord> ParseCsv(std::string_view text, const std::string& origin) {
  std::vector<CsvRecord> records;
  std::size_t line = 1, i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    // An empty line (LF or CRLF) holds no record.
    if (text[i] == '\n' || (text[i] == '\r' && i + 1 < n && text[i + 1] == '\n')) {
      i += text[i] == '\r' ? 2 : 1;
      ++line;
      continue;
    }
    CsvRecord r;
    r.line = line;
    std::string field;
    bool done = false;
    while (!done) {
      if (i < n && text[i] == '"') {  // a quoted field
        const std::size_t opened = line;
        ++i;
        while (true) {
          if (i >= n) throw InputError(origin + ":" + std::to_string(opened) + ": a quoted field is never closed");
          const char c = text[i++];
          if (c == '"') {
            if (i < n && text[i] == '"') {
              field += '"';
              ++i;
              continue;
            }
            break;
          }
          if (c == '\n') ++line;
          field += c;
        }
        if (i < n && text[i] != ',' && text[i] != '\n' && !(text[i] == '\r' && i + 1 < n && text[i + 1] == '\n'))
          throw InputError(origin + ":" + std::to_string(line) + ": text after a quoted field; expected a comma or the line's end");
      } else {  // an unquoted field, up to a comma or the line's end
        while (i < n && text[i] != ',' && text[i] != '\n' && !(text[i] == '\r' && i + 1 < n && text[i + 1] == '\n')) {
          if (text[i] == '"')
            throw InputError(origin + ":" + std::to_string(line) +
                             ": a double quote inside an unquoted field; expected the field quoted (\"...\") with its quotes doubled");
          field += text[i++];
        }
      }
      r.fields.push_back(std::move(field));
      field.clear();
      if (i < n && text[i] == ',') {
        ++i;
        continue;
      }
      done = true;  // the line's end, or the text's
      if (i < n) {
        i += text[i] == '\r' ? 2 : 1;
        ++line;
      }
    }
    records.push_back(std::move(r));
  }
  return records;
}

}  // namespace crowdrecon
