#include "granmem/core/lammps_dump.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>

#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

// The file, line by line, with the place of the current line for messages.
class DumpLines {
 public:
  explicit DumpLines(const std::filesystem::path& path)
      : in_(path, std::ios::binary), where_(path.string()) {
    if (!in_) throw Error(where_ + ": cannot open for reading");
  }
  bool next() {
    if (!std::getline(in_, line_)) return false;
    ++number_;
    if (!line_.empty() && line_.back() == '\r') line_.pop_back();
    return true;
  }
  // The next line, which the dump's grammar requires: `what` names it in the message.
  const std::string& expect(const std::string& what) {
    if (!next())
      throw Error(where_ + ": ends where " + what + " should follow (line " +
                  std::to_string(number_ + 1) + ")");
    return line_;
  }
  const std::string& line() const { return line_; }
  std::size_t number() const { return number_; }
  std::string at() const { return where_ + " line " + std::to_string(number_); }
  const std::string& file() const { return where_; }

 private:
  std::ifstream in_;
  std::string where_, line_;
  std::size_t number_ = 0;
};

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t'))
      ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t')
      ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

double number(std::string_view word, const DumpLines& in, const std::string& what) {
  double v = 0;
  const char* begin = word.data() + (!word.empty() && word.front() == '+');
  const auto [end, ec] = std::from_chars(begin, word.data() + word.size(), v);
  if (ec != std::errc() || end != word.data() + word.size()) {
    throw Error(in.at() + ": " + what + ": expected a number, found '" + std::string(word) + "'");
  }
  return v;
}

long long count(std::string_view line, const DumpLines& in, const std::string& what) {
  const std::string_view w = trim(line);
  long long v = 0;
  const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
  if (ec != std::errc() || end != w.data() + w.size() || v < 0) {
    throw Error(in.at() + ": " + what + ": expected a whole number, found '" + std::string(w) +
                "'");
  }
  return v;
}

// Where each of a snapshot's ATOMS columns goes in granmem's table.
struct AtomColumns {
  std::string header;            // the ITEM: ATOMS line, the same in every snapshot
  std::vector<int> target;       // per dump column: index into kTargets, or -1 (read past)
  std::array<bool, 3> scaled{};  // x, y, z given as fractions of the box
  bool diameter = false;
  int id = -1, type = -1;
};

// granmem's columns and the dump names that fill them.
const std::vector<std::pair<std::string, std::vector<std::string>>> kTargets{
    {"x", {"x", "xu", "xs", "xsu"}},
    {"y", {"y", "yu", "ys", "ysu"}},
    {"z", {"z", "zu", "zs", "zsu"}},
    {"radius", {"radius", "diameter"}},
    {"ax", {"ax", "mux"}},  // a dipole carried with the grain (sim/lammps/cycles.lmp)
    {"ay", {"ay", "muy"}},
    {"az", {"az", "muz"}},
    {"qw", {"quatw", "qw"}},
    {"qx", {"quati", "qx"}},
    {"qy", {"quatj", "qy"}},
    {"qz", {"quatk", "qz"}},
    {"hole_contact", {"hole_contact"}}};

AtomColumns atom_columns(const std::string& item, const DumpLines& in) {
  AtomColumns c;
  c.header = item;
  const std::vector<std::string_view> names = words(item);  // ITEM: ATOMS name...
  for (std::size_t k = 2; k < names.size(); ++k) {
    const std::string name(names[k]);
    int target = -1;
    for (std::size_t t = 0; t < kTargets.size(); ++t) {
      for (const std::string& alias : kTargets[t].second) {
        if (alias == name) target = int(t);
      }
    }
    if (name == "id") c.id = int(k - 2);
    if (name == "type") c.type = int(k - 2);
    if (target >= 0) {
      for (int seen : c.target) {
        if (seen == target) {
          throw Error(in.at() + ": two columns give '" + kTargets[std::size_t(target)].first +
                      "' (" + item.substr(12) + ")");
        }
      }
      if (target < 3) c.scaled[std::size_t(target)] = name[1] == 's';
      if (name == "diameter") c.diameter = true;
    }
    c.target.push_back(target);
  }
  if (c.id < 0) throw Error(in.at() + ": the atoms have no 'id' column");
  for (int axis = 0; axis < 3; ++axis) {
    if (std::find(c.target.begin(), c.target.end(), axis) == c.target.end()) {
      throw Error(in.at() + ": the atoms have no " + kTargets[std::size_t(axis)].first +
                  " position (x, xu, xs or xsu)");
    }
  }
  return c;
}

// One snapshot's ITEM: BOX BOUNDS and its three lines.
Box box_bounds(const std::string& item, DumpLines& in) {
  if (item.find("xy") != std::string::npos || item.find("abc") != std::string::npos) {
    throw Error(in.at() + ": a triclinic box; granmem's containers are orthogonal boxes");
  }
  Box b;
  for (int k = 0; k < 3; ++k) {
    const std::vector<std::string_view> w = words(in.expect("the box's bounds"));
    if (w.size() != 2) throw Error(in.at() + ": expected the box's two bounds, lo hi");
    const double lo = number(w[0], in, "box bound"), hi = number(w[1], in, "box bound");
    if (!(hi >= lo) || !std::isfinite(lo) || !std::isfinite(hi)) {
      throw Error(in.at() + ": box bounds " + std::string(w[0]) + " " + std::string(w[1]) +
                  ": expected finite lo <= hi");
    }
    b.lower[k] = lo;
    b.edges[k] = hi - lo;
  }
  return b;
}

class DumpReader {
 public:
  DumpReader(const std::filesystem::path& path, const std::set<long long>& types)
      : in_(path), types_(types) {}

  LammpsDump read() {
    while (in_.next()) {
      const std::string_view t = trim(in_.line());
      if (t.empty()) continue;
      if (t.rfind("ITEM: UNITS", 0) == 0) {
        dump_.units = std::string(trim(in_.expect("the units style")));
      } else if (t.rfind("ITEM: TIMESTEP", 0) == 0) {
        snapshot();
      } else {
        throw Error(in_.at() + ": expected 'ITEM: TIMESTEP' (is this a LAMMPS text dump?)");
      }
    }
    if (dump_.snapshots == 0) throw Error(in_.file() + ": no snapshot (ITEM: TIMESTEP)");
    return std::move(dump_);
  }

 private:
  void snapshot() {
    const long long step = count(in_.expect("the timestep"), in_, "timestep");
    long long atoms = -1;
    std::optional<Box> box;
    while (true) {
      const std::string item(trim(in_.expect("ITEM: ATOMS")));
      if (item.rfind("ITEM: TIME", 0) == 0 && item.size() == 10) {
        in_.expect("the time");
      } else if (item.rfind("ITEM: NUMBER OF ATOMS", 0) == 0) {
        atoms = count(in_.expect("the number of atoms"), in_, "number of atoms");
      } else if (item.rfind("ITEM: BOX BOUNDS", 0) == 0) {
        box = box_bounds(item, in_);
      } else if (item.rfind("ITEM: ATOMS", 0) == 0) {
        if (atoms < 0 || !box) {
          throw Error(in_.at() + ": ITEM: ATOMS before the number of atoms and the box");
        }
        atoms_of(item, step, std::size_t(atoms), *box);
        return;
      } else {
        throw Error(in_.at() + ": unexpected '" + item.substr(0, 40) + "' in a snapshot");
      }
    }
  }

  void begin_table(const std::string& item) {
    columns_ = atom_columns(item, in_);
    if (!types_.empty() && columns_.type < 0) {
      throw Error(in_.at() + ": atom types were asked for, but the dump has no 'type' column");
    }
    Table& t = dump_.table;
    t.add("frame", "", true);
    t.add("particle", "", true);
    for (std::size_t k = 0; k < kTargets.size(); ++k) {
      if (std::find(columns_.target.begin(), columns_.target.end(), int(k)) !=
          columns_.target.end()) {
        t.add(kTargets[k].first, "", kTargets[k].first == "hole_contact");
      }
    }
  }

  void atoms_of(const std::string& item, long long step, std::size_t atoms, const Box& box) {
    if (dump_.snapshots == 0) {
      begin_table(item);
      dump_.box = box;
    } else if (item != columns_.header) {
      throw Error(in_.at() + ": the atoms' columns differ from the first snapshot's ('" +
                  columns_.header + "')");
    } else if (box.lower != dump_.box->lower || box.edges != dump_.box->edges) {
      dump_.box_changes = true;
    }
    ++dump_.snapshots;
    Table& t = dump_.table;
    std::vector<double> row(columns_.target.size());
    for (std::size_t a = 0; a < atoms; ++a) {
      const std::vector<std::string_view> w = words(in_.expect("an atom's line"));
      if (w.size() != row.size()) {
        throw Error(in_.at() + ": " + std::to_string(w.size()) +
                    " fields where the ATOMS line has " + std::to_string(row.size()) + " columns");
      }
      for (std::size_t k = 0; k < w.size(); ++k)
        row[k] = number(w[k], in_, "column " + std::to_string(k + 1));
      if (!types_.empty() && !kept_type(row[std::size_t(columns_.type)])) continue;
      t["frame"].values.push_back(double(step));
      // granmem's export writes atom id = grain id + 1 (LAMMPS counts from 1).
      t["particle"].values.push_back(row[std::size_t(columns_.id)] - 1);
      for (std::size_t k = 0; k < row.size(); ++k) {
        const int target = columns_.target[k];
        if (target < 0) continue;
        double v = row[k];
        if (target < 3 && columns_.scaled[std::size_t(target)]) {
          v = box.lower[target] + v * box.edges[target];
        }
        if (target == 3 && columns_.diameter) v *= 0.5;
        t[kTargets[std::size_t(target)].first].values.push_back(v);
      }
      dump_.lines.push_back(in_.number());
    }
  }

  bool kept_type(double type) const {
    if (!(std::abs(type) < 1e15) || type != std::floor(type)) {
      throw Error(in_.at() + ": the atom's type is not a whole number");
    }
    return types_.count(static_cast<long long>(type)) > 0;
  }

  DumpLines in_;
  const std::set<long long>& types_;
  AtomColumns columns_;
  LammpsDump dump_;
};

}  // namespace

LammpsDump read_lammps_dump(const std::filesystem::path& path, const std::set<long long>& types) {
  return DumpReader(path, types).read();
}

std::string lammps_length_unit(const std::string& units_style) {
  static const std::map<std::string, std::string> unit{{"si", "m"}, {"cgs", "cm"}, {"micro", "um"}};
  const auto u = unit.find(units_style);
  return u == unit.end() ? "" : u->second;
}

}  // namespace granmem
