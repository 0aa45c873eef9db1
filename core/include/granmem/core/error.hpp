#pragma once

#include <stdexcept>
#include <string>

namespace granmem {

// Bad input or an impossible request. The message names the file, the field and
// what was expected, in one line; only app/ turns it into an exit code.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace granmem
