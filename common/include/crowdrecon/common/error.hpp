// Errors of crowdrecon. Every error a user can cause is an InputError whose
// message names where the problem is (file, JSON path or line, element), the
// value found and what was expected. The command-line program prints the
// message and exits non-zero.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace crowdrecon {

// Bad input: a file, option or value the user gave.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A part of crowdrecon's own installation is missing or broken (not the
// user's input, not a bug): the message says what and how to mend it.
class SetupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Invalid geometry (a shape or venue that cannot be built as asked).
class GeometryError : public InputError {
 public:
  using InputError::InputError;
};

// Formats a double compactly for messages ("0.05", "1e+05").
std::string FormatNumber(double value);
// Formats a double with a fixed number of decimals ("0.405" for 3).
std::string FormatFixed(double value, int decimals);

// `text` cut to at most `max_chars` characters ("..." marks a cut; a UTF-8
// sequence is never split), for echoing what a user gave in a message.
std::string ShortText(std::string_view text, std::size_t max_chars = 60);

// Formats a duration in seconds for progress lines: "42s", "3m07s", "1h05m";
// "?" if not finite.
std::string FormatDuration(double seconds);

}  // namespace crowdrecon
