#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "granmem/sim/simulation.hpp"

namespace granmem {

// Where a protocol stands, beside the simulation's state, so that a run stopped at any
// step and resumed gives the same result bit for bit.
struct ProtocolState {
  std::int64_t cycles_done = 0;    // completed cycles
  std::int64_t step_in_cycle = 0;  // steps taken in the cycle under way
  // Frames already in each output (end_of_cycle, full_compression, in_cycle), and values
  // measured earlier in the cycle under way.
  std::map<std::string, std::int64_t> frames_written;
  std::map<std::string, double> pending;
  // The settings of the run (option -> value), checked and reused on resume.
  std::map<std::string, std::string> settings;
};

// The full state: grains (positions, velocities, orientations, forces), container, lid,
// every contact's history, the physics, time, and the protocol state. Written atomically.
void write_checkpoint(const std::filesystem::path& path, const Simulation& sim,
                      const ProtocolState& protocol);

// A simulation exactly as it was when the checkpoint was written.
Simulation read_checkpoint(const std::filesystem::path& path, ProtocolState* protocol = nullptr);

}  // namespace granmem
