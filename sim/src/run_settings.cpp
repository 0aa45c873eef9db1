#include "granmem/sim/run_settings.hpp"

#include "granmem/core/error.hpp"

namespace granmem {

RunSettings resumed_settings(RunSettings& recorded, const RunSettings& current,
                             const std::set<std::string>& given,
                             const std::set<std::string>& may_change) {
  RunSettings merged = current;
  std::string changeable;
  for (const std::string& name : may_change)
    changeable += (changeable.empty() ? "--" : " and --") + name;
  for (auto& [key, value] : recorded) {
    const auto now = current.find(key);
    if (given.count(key) && now != current.end() && now->second != value) {
      if (!may_change.count(key)) {
        throw Error("--" + key + " " + now->second + ": a resumed run keeps its settings (" +
                    value + "); only " + changeable + " change");
      }
      value = now->second;
    }
    merged[key] = value;
  }
  return merged;
}

RunSettings started_from_settings(const RunSettings& trained, const RunSettings& current,
                                  const std::set<std::string>& given,
                                  const std::vector<std::string>& packing,
                                  const std::set<std::string>& optional,
                                  const std::string& source) {
  RunSettings merged = current;
  for (const std::string& name : packing) {
    const auto it = trained.find(name);
    if (it == trained.end()) {
      if (optional.count(name)) continue;
      throw Error(source + ": has no setting '" + name + "' (was it written by granmem simulate?)");
    }
    const auto now = current.find(name);
    if (given.count(name) && now != current.end() && now->second != it->second) {
      throw Error("--" + name + " " + now->second +
                  ": with --start-from the packing and its physics are the checkpoint's (" +
                  it->second + ")");
    }
    merged[name] = it->second;
  }
  return merged;
}

}  // namespace granmem
