#include "granmem/sim/lammps_data.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"

namespace granmem {
namespace {

constexpr double kCm = 0.01;  // m per cm

// atom_style sphere: id type diameter density x y z; hybrid sphere dipole: id type x y z,
// then each sub-style's columns (diameter density, then charge and dipole).
void write_atom(std::ostream& out, std::size_t id, int type, const Eigen::Vector3d& x_cm,
                double diameter_cm, double density_cgs, const Eigen::Vector3d* dipole) {
  out << id << " " << type << " ";
  if (!dipole) {
    out << diameter_cm << " " << density_cgs << " " << x_cm.x() << " " << x_cm.y() << " "
        << x_cm.z() << "\n";
    return;
  }
  out << x_cm.x() << " " << x_cm.y() << " " << x_cm.z() << " " << diameter_cm << " " << density_cgs
      << " 0 " << dipole->x() << " " << dipole->y() << " " << dipole->z() << "\n";
}

void write_atoms(std::ostream& out, const Grains& g, const Container& c,
                 const LammpsDataOptions& o) {
  const double rho_cgs = o.density * 1e-3;  // kg/m^3 -> g/cm^3
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d axis = g.q[i] * Eigen::Vector3d::UnitZ();
    write_atom(out, std::size_t(g.id[i] + 1), 1, g.x[i] / kCm, 2 * g.radius[i] / kCm, rho_cgs,
               o.cavity_axis_as_dipole ? &axis : nullptr);
  }
  if (c.lid.present) {
    // A point particle: diameter 0, so the density column is its mass in g.
    const Eigen::Vector3d none = Eigen::Vector3d::Zero();
    write_atom(out, g.size() + 1, 2,
               Eigen::Vector3d(0.5 * c.size.x(), 0.5 * c.size.y(), c.lid.z) / kCm, 0,
               c.lid.mass * 1e3, o.cavity_axis_as_dipole ? &none : nullptr);
  }
}

}  // namespace

void write_lammps_data(const std::filesystem::path& path, const Grains& g, const Container& c,
                       const LammpsDataOptions& o) {
  AtomicFile file(path);
  std::ofstream out(file.temp_path());
  if (!out) throw Error(path.string() + ": cannot write");
  double top = 0;
  for (std::size_t i = 0; i < g.size(); ++i)
    top = std::max(top, g.x[i].z() + g.radius[i]);
  if (c.lid.present) top = std::max(top, c.lid.z);
  const double lx = c.size.x() / kCm, ly = c.size.y() / kCm;
  const double zhi = std::max(4.0 * ly, 2.0 * top / kCm + 1.0);
  const std::size_t atoms = g.size() + (c.lid.present ? 1 : 0);
  out << "LAMMPS data file (CGS) from granmem: " << o.comment << "\n\n"
      << atoms << " atoms\n2 atom types\n\n"
      << std::setprecision(12) << 0.0 << " " << lx << " xlo xhi\n"
      << 0.0 << " " << ly << " ylo yhi\n"
      << -0.5 << " " << zhi << " zlo zhi\n\nAtoms # "
      << (o.cavity_axis_as_dipole ? "hybrid sphere dipole" : "sphere") << "\n\n"
      << std::setprecision(17);
  write_atoms(out, g, c, o);
  out << "\nVelocities\n\n";
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d v = g.v[i] / kCm;
    out << g.id[i] + 1 << " " << v.x() << " " << v.y() << " " << v.z() << " " << g.w[i].x() << " "
        << g.w[i].y() << " " << g.w[i].z() << "\n";
  }
  if (c.lid.present) out << g.size() + 1 << " 0 0 " << c.lid.v / kCm << " 0 0 0\n";
  out.close();
  if (!out) throw Error(path.string() + ": cannot write (disk full?)");
  file.commit();
}

}  // namespace granmem
