#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace granmem {

// The settings of a simulated run as text, option name -> value as given ("0.5cm"): what
// `granmem simulate` records in a checkpoint (ProtocolState::settings), and how a run that
// goes on from a checkpoint merges them with the settings of the new call. `current` holds
// every option of the new call (defaults and given); `given` names those set explicitly.
using RunSettings = std::map<std::string, std::string>;

// --resume: the run goes on with its recorded settings; an option given anew with another
// value is taken only if it is in `may_change` (and then recorded), else Error. Options
// the checkpoint lacks (newer than it) keep their current values.
RunSettings resumed_settings(RunSettings& recorded, const RunSettings& current,
                             const std::set<std::string>& given,
                             const std::set<std::string>& may_change);

// --start-from `source`: a new protocol from a trained packing. The `packing` options (the
// grains and their physics) are the trained run's, and one given anew with another value is
// an Error; every other option is the new call's. A packing option the checkpoint lacks is
// an Error unless it is in `optional` (an option newer than the checkpoint).
RunSettings started_from_settings(const RunSettings& trained, const RunSettings& current,
                                  const std::set<std::string>& given,
                                  const std::vector<std::string>& packing,
                                  const std::set<std::string>& optional, const std::string& source);

}  // namespace granmem
