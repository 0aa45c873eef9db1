#include "granmem/core/error.hpp"

#include <algorithm>

namespace granmem {

std::string one_printable_line(std::string_view message, std::size_t max_bytes) {
  std::string out;
  out.reserve(std::min(message.size(), max_bytes) + 32);
  std::size_t k = 0;
  for (; k < message.size() && out.size() < max_bytes; ++k) {
    const unsigned char c = static_cast<unsigned char>(message[k]);
    if (c < 0x20 || c == 0x7f) {
      constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += char(c);
    }
  }
  if (k < message.size()) out += "... (" + std::to_string(message.size() - k) + " more bytes)";
  return out;
}

}  // namespace granmem
