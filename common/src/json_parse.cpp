#include "json_parse.hpp"

#include <iterator>
#include <map>
#include <optional>
#include <vector>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::detail {

namespace {

using json = nlohmann::json;

// An input iterator over the text that records the last character the lexer
// took, so that SAX events (which carry no position) can be placed in the file.
class TrackingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  TrackingIterator(const char* at, const char** last_read) : at_(at), last_read_(last_read) {}
  char operator*() const {
    *last_read_ = at_;
    return *at_;
  }
  TrackingIterator& operator++() {
    ++at_;
    return *this;
  }
  bool operator==(const TrackingIterator& other) const { return at_ == other.at_; }
  bool operator!=(const TrackingIterator& other) const { return at_ != other.at_; }

 private:
  const char* at_;
  const char** last_read_;
};

// Builds the document from SAX events (as nlohmann's own DOM parser does) and
// checks depth, duplicate keys and number overflow on the way.
class CheckedDomBuilder {
 public:
  using number_integer_t = json::number_integer_t;
  using number_unsigned_t = json::number_unsigned_t;
  using number_float_t = json::number_float_t;
  using string_t = json::string_t;
  using binary_t = json::binary_t;

  CheckedDomBuilder(std::string_view text, const std::string& origin) : text_(text), origin_(origin) {}

  const char** last_read() { return &last_read_; }
  json& root() { return root_; }
  const std::optional<std::string>& error() const { return error_; }

  bool null() { return Put(nullptr); }
  bool boolean(bool v) { return Put(v); }
  bool number_integer(number_integer_t v) { return Put(v); }
  bool number_unsigned(number_unsigned_t v) { return Put(v); }
  bool number_float(number_float_t v, const string_t&) { return Put(v); }
  bool string(string_t& v) { return Put(std::move(v)); }
  bool binary(binary_t& v) { return Put(json::binary(std::move(v))); }
  bool start_object(std::size_t) { return Open(json::object()); }
  bool start_array(std::size_t) { return Open(json::array()); }
  bool end_object() { return Close(); }
  bool end_array() { return Close(); }

  bool key(string_t& k) {
    Frame& frame = stack_.back();
    const std::size_t offset = Offset();
    if (const auto first = frame.key_offsets.find(k); first != frame.key_offsets.end()) {
      duplicate_ = Duplicate{stack_.size(), frame.path + "/" + EscapeToken(k), SketchJson(frame.value->at(k)),
                             first->second, offset};
    } else {
      frame.key_offsets.emplace(k, offset);
    }
    frame.key = std::move(k);
    return true;
  }

  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& ex) {
    std::string what = ex.what();
    // nlohmann's message starts with "[json.exception.parse_error.101] parse error at ...".
    if (const auto pos = what.find("] "); pos != std::string::npos) what = what.substr(pos + 2);
    if (ex.id == 406)  // out_of_range: a number beyond the range of a double
      what = "number " + ShortText(token) + " is beyond the range of a double (about +-1.8e308); expected a finite number";
    else
      what = "invalid JSON: " + ShortText(what, 300);
    error_ = TextPosition(text_, position > 0 ? position - 1 : 0, origin_) + ": " + what;
    return false;
  }

 private:
  struct Frame {
    json* value;
    std::string path;
    std::string key;                                // the key whose value comes next (objects)
    std::map<std::string, std::size_t, std::less<>> key_offsets;  // where each key was read
  };
  struct Duplicate {
    std::size_t depth;
    std::string path;
    std::string first_value;
    std::size_t first_offset, second_offset;
  };

  std::size_t Offset() const { return last_read_ ? static_cast<std::size_t>(last_read_ - text_.data()) : 0; }

  // Where the next value goes, and its path.
  std::pair<json*, std::string> Slot() {
    if (stack_.empty()) return {&root_, ""};
    Frame& frame = stack_.back();
    if (frame.value->is_array()) {
      const std::string path = frame.path + "/" + std::to_string(frame.value->size());
      frame.value->push_back(nullptr);
      return {&frame.value->back(), path};
    }
    return {&(*frame.value)[frame.key], frame.path + "/" + EscapeToken(frame.key)};
  }

  bool Put(json value) {
    *Slot().first = std::move(value);
    return ValueDone();
  }

  bool Open(json container) {
    if (stack_.size() >= kMaxJsonDepth) {
      error_ = TextPosition(text_, Offset(), origin_) + ": objects and arrays nested more than " +
               std::to_string(kMaxJsonDepth) + " levels deep (at " + ShortText(stack_.back().path) +
               "); expected a crowdrecon input, which nests a few levels";
      return false;
    }
    auto [slot, path] = Slot();
    *slot = std::move(container);
    stack_.push_back(Frame{slot, std::move(path), {}, {}});
    return true;
  }

  bool Close() {
    stack_.pop_back();
    return ValueDone();
  }

  // After a complete value: a duplicate key whose second value is now read is reported.
  bool ValueDone() {
    if (!duplicate_ || stack_.size() != duplicate_->depth) return true;
    const Duplicate& d = *duplicate_;
    const json& second = stack_.back().value->at(stack_.back().key);
    error_ = TextPosition(text_, d.second_offset, origin_) + ": " + ShortText(d.path) +
             ": key given twice (first at line " + Line(d.first_offset) + " with value " + d.first_value +
             ", again at line " + Line(d.second_offset) + " with value " + SketchJson(second) +
             "); expected each key once per object";
    return false;
  }

  std::string Line(std::size_t offset) const {
    std::size_t line = 1;
    for (std::size_t i = 0; i < offset && i < text_.size(); ++i) line += text_[i] == '\n';
    return std::to_string(line);
  }

  std::string_view text_;
  const std::string& origin_;
  const char* last_read_ = nullptr;
  json root_;
  std::vector<Frame> stack_;
  std::optional<Duplicate> duplicate_;
  std::optional<std::string> error_;
};

void Sketch(const json& value, std::size_t max_chars, int depth, std::string& out) {
  constexpr int kMaxDepth = 4;
  if (out.size() > max_chars) return;
  if (value.is_string()) {
    out += json(ShortText(value.get_ref<const std::string&>(), max_chars)).dump();
  } else if (!value.is_structured()) {
    out += value.dump();
  } else if (depth >= kMaxDepth) {
    out += value.is_array() ? "[...]" : "{...}";
  } else {
    const bool array = value.is_array();
    out += array ? '[' : '{';
    bool first = true;
    for (auto it = value.begin(); it != value.end() && out.size() <= max_chars; ++it) {
      out += first ? "" : ", ";
      first = false;
      if (!array) out += json(ShortText(it.key(), max_chars)).dump() + ": ";
      Sketch(*it, max_chars, depth + 1, out);
    }
    out += array ? ']' : '}';
  }
}

}  // namespace

std::string EscapeToken(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string TextPosition(std::string_view text, std::size_t offset, const std::string& origin) {
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return origin + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string SketchJson(const json& value, std::size_t max_chars) {
  std::string out;
  Sketch(value, max_chars, 0, out);
  return ShortText(out, max_chars);
}

json ParseJsonText(std::string_view text, const std::string& origin) {
  CheckedDomBuilder builder(text, origin);
  const TrackingIterator first(text.data(), builder.last_read());
  const TrackingIterator last(text.data() + text.size(), builder.last_read());
  bool ok = false;
  try {
    ok = json::sax_parse(first, last, &builder);
  } catch (const nlohmann::json::exception& e) {  // any other library error: still the user's input
    throw InputError(origin + ": invalid JSON: " + ShortText(e.what(), 300));
  }
  if (builder.error()) throw InputError(*builder.error());
  if (!ok) throw InputError(origin + ": invalid JSON");
  return std::move(builder.root());
}

}  // namespace crowdrecon::detail
