#include "granmem/core/json_file.hpp"

#include <fstream>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// Text that is not UTF-8 (a path, a setting) is written with replacement characters
// rather than refused.
std::string dump(const JsonObject& value) {
  return value.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

}  // namespace

void write_json(const std::filesystem::path& path, const JsonObject& object) {
  if (!object.is_object()) throw Error(path.string() + ": a JSON summary must be an object");
  AtomicFile file(path);
  std::ofstream out(file.temp_path());
  out << "{";
  bool first = true;
  for (const auto& [key, value] : object.items()) {
    out << (first ? "\n  " : ",\n  ") << dump(JsonObject(key)) << ": " << dump(value);
    first = false;
  }
  out << "\n}\n";
  out.close();
  if (!out) throw Error(path.string() + ": could not write");
  file.commit();
}

}  // namespace granmem
