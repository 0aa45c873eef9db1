#pragma once

#include <cstdint>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

// Command lines of the benchmarks: `--name value` options and `--name` flags, each handled
// by its setter. False (with a line on stderr) for an unknown name or a missing value.
namespace granmem::bench {

using Setters = std::map<std::string, std::function<void(const std::string&)>>;
using Flags = std::map<std::string, std::function<void()>>;

inline bool parse_options(int argc, char** argv, const std::string& program, const Setters& options,
                          const Flags& flags = {}) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (const auto f = flags.find(a); f != flags.end()) {
      f->second();
      continue;
    }
    const auto o = options.find(a);
    if (o == options.end()) {
      std::cerr << program << ": unknown option " << a << "\n";
      return false;
    }
    if (i + 1 >= argc) {
      std::cerr << program << ": " << a << " needs a value\n";
      return false;
    }
    o->second(argv[++i]);
  }
  return true;
}

// "8,12,16" -> {8, 12, 16}.
inline std::vector<double> number_list(const std::string& s) {
  std::vector<double> v;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    v.push_back(std::stod(item));
  return v;
}

// What the benchmarks on rendered packings share: the packings, the scans, the threads.
struct ScanBenchOptions {
  std::size_t grains = 2000;
  double phi = 0.59;
  std::vector<double> diameters{8, 12, 16}, z_ratios{1, 1.5}, bits{8, 16};
  int threads = 2;
  std::uint32_t seed = 1;
  std::string out;  // CSV

  Setters setters() {
    return {{"--grains", [this](const std::string& v) { grains = std::size_t(std::stoul(v)); }},
            {"--phi", [this](const std::string& v) { phi = std::stod(v); }},
            {"--diameters", [this](const std::string& v) { diameters = number_list(v); }},
            {"--z-ratios", [this](const std::string& v) { z_ratios = number_list(v); }},
            {"--bits", [this](const std::string& v) { bits = number_list(v); }},
            {"--threads", [this](const std::string& v) { threads = std::stoi(v); }},
            {"--seed", [this](const std::string& v) { seed = std::uint32_t(std::stoul(v)); }},
            {"--out", [this](const std::string& v) { out = v; }}};
  }
};

}  // namespace granmem::bench
