#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace granmem {

// Bad input or an impossible request. The message names the file, the field and
// what was expected, in one line; only app/ turns it into an exit code.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A message as one printable line: control bytes (a NUL, a line end, an escape sequence
// from a damaged file) shown as \xNN, and at most `max_bytes` bytes of it, the rest
// counted. Messages echo what a file held, which may be anything and of any length.
std::string one_printable_line(std::string_view message, std::size_t max_bytes = 2000);

}  // namespace granmem
