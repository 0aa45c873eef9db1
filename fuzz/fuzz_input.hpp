#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

// What the fuzz harnesses share: the input written to a file of this process (the parsers
// read files, as users give them).
namespace granmem::fuzz {

inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size,
                                        const std::string& extension) {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("granmem-fuzz-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / ("input" + extension);
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return file;
}

}  // namespace granmem::fuzz
