#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

namespace granmem {

// A JSON object whose members keep the order they were added in.
using JsonObject = nlohmann::ordered_json;

// Writes `object` through the atomic writer, one member a line with its value on that line
// (arrays and objects compact), so that line tools read a member as well as JSON parsers
// do. Non-finite numbers are written as null.
void write_json(const std::filesystem::path& path, const JsonObject& object);

}  // namespace granmem
