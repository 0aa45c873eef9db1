#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"

namespace granmem::app {
namespace {

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

void print_datasets(const h5::File& file) {
  for (const h5::DatasetInfo& d : h5::list_datasets(file)) {
    std::cout << "    " << d.path << " " << h5::shape_text(d.dims);
    if (!d.unit.empty() && d.unit != "1") std::cout << " [" << d.unit << "]";
    std::cout << "\n";
  }
}

}  // namespace

void add_info(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Print what a trajectory store holds");
  cmd->add_option("file", *path, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->callback([path] {
    const TrajectoryReader run(*path);
    const RunHeader& h = run.header();
    const auto& steps = run.steps();
    std::cout << *path << ": trajectory store (H5MD), group " << run.particles_group() << "\n";
    std::cout << "  producer    " << h.creator_name << " " << h.creator_version;
    if (!h.author.empty()) std::cout << ", author " << h.author;
    std::cout << "\n  frames      " << run.frame_count();
    if (!steps.empty()) std::cout << " (steps " << steps.front() << " to " << steps.back() << ")";
    std::cout << ", sample " << h.sample << ", time in " << h.time_unit << "\n";
    std::size_t known = 0;
    double sum = 0;
    for (double r : h.radius) {
      if (std::isfinite(r)) {
        ++known;
        sum += r;
      }
    }
    std::cout << "  grains      " << h.grain_count();
    if (known) std::cout << ", mean radius " << sum / double(known) << " " << h.length_unit;
    if (known < h.grain_count()) std::cout << ", radius unknown for " << h.grain_count() - known;
    std::cout << "\n  lengths     " << h.length_unit;
    if (h.voxel_size) std::cout << ", voxel size " << vec(*h.voxel_size) << " " << h.length_unit;
    std::cout << "\n  box         ";
    if (h.box) {
      std::cout << "lower " << vec(h.box->lower) << ", edges " << vec(h.box->edges) << " "
                << h.length_unit;
    } else {
      std::cout << "none";
    }
    std::cout << "\n  per grain   position";
    if (h.has_axis) std::cout << ", cavity axis";
    if (h.has_orientation) std::cout << ", orientation";
    if (h.has_hole_contact) std::cout << ", hole contact flag";
    std::cout << "\n";
    if (!run.observables().empty()) {
      std::cout << "  observables";
      for (const auto& [name, obs] : run.observables()) {
        std::cout << " " << name << " [" << obs.unit << "] (" << obs.value.size() << ")";
      }
      std::cout << "\n";
    }
    if (!h.parameters.empty()) {
      std::cout << "  parameters\n";
      for (const auto& [key, value] : h.parameters) {
        std::cout << "    " << key << " = " << value << "\n";
      }
    }
    std::cout << "  datasets\n";
    print_datasets(run.file());
  });
}

}  // namespace granmem::app
