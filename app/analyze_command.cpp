#include <charconv>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"
#include "granmem/rotation/analyze_run.hpp"

namespace granmem::app {
namespace {

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

}  // namespace

void analyze_and_report(const TrajectoryReader& run, const AnalysisOptions& options,
                        const std::string& out, const std::map<std::string, std::string>& used) {
  const AnalyzeSummary summary = analyze_run(run, options, out, used);
  for (const std::string& note : summary.notes)
    std::cerr << "granmem: note: " << note << "\n";
  std::cout << summary.Report();
}

void add_analyze(CLI::App& app) {
  struct Args {
    std::string run, out, wall_distance = "0", container, hole_contacts = "keep", pdf, window,
                          pdf_scale = "linear", pdf_range;
    bool subtract_drift = false;
    std::size_t pdf_bins = 50;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "analyze", "Displacements and rotations between consecutive frames, per-frame means, pdfs");
  cmd->add_option("run", args->run, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "output folder")->required();
  add_drift_flags(cmd, args->subtract_drift);
  cmd->add_option("--wall-distance", args->wall_distance,
                  "leave out grains whose centre is closer than this to a container face "
                  "(run's length unit, or give one: 0.5cm)")
      ->capture_default_str();
  cmd->add_option("--container", args->container,
                  "container xmin,ymin,zmin,xmax,ymax,zmax (run's unit); default the run's box");
  cmd->add_option("--hole-contacts", args->hole_contacts,
                  "grains touching through their hole: keep, exclude-rotations, exclude")
      ->check(CLI::IsMember({"keep", "exclude-rotations", "exclude"}))
      ->capture_default_str();
  cmd->add_option("--pdf", args->pdf,
                  "quantities for pdfs, comma list (dr,dx,dy,dz,theta_axis_deg,rot_disp,"
                  "theta_full_deg); default all the run has");
  cmd->add_option("--window", args->window,
                  "FIRST:LAST frames (labels: cycles or scans) pooled into the pdfs; default all");
  cmd->add_option("--pdf-bins", args->pdf_bins, "number of bins")
      ->check(CLI::Validator(
          [](std::string& text) {
            // CLI::PositiveNumber would say "not in range 0.000000 to <309 digits>".
            unsigned long long bins = 0;
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), bins);
            const bool ok = ec == std::errc() && end == text.data() + text.size() && bins > 0;
            return ok ? std::string()
                      : "expected a whole number of bins, at least 1, got '" + text + "'";
          },
          "POSITIVE"))
      ->capture_default_str();
  cmd->add_option("--pdf-scale", args->pdf_scale, "linear or log bins")
      ->check(CLI::IsMember({"linear", "log"}))
      ->capture_default_str();
  cmd->add_option("--pdf-range", args->pdf_range, "LO:HI of the bins; default the data's range");

  cmd->callback([args, cmd] {
    const TrajectoryReader run(args->run);
    const RunHeader& h = run.header();
    AnalysisOptions options;
    options.motion.subtract_drift = args->subtract_drift;
    options.motion.wall_distance =
        parse_length(args->wall_distance, h.length_unit, "--wall-distance");
    if (!args->container.empty()) options.motion.box = parse_box(args->container, "--container");
    options.motion.hole_contacts = hole_contact_policy(args->hole_contacts, "--hole-contacts");
    options.pdf_quantities = split_list(args->pdf);
    if (!args->window.empty()) options.pdf_frames = parse_int_range(args->window, "--window");
    options.density.bins = args->pdf_bins;
    options.density.scale = args->pdf_scale == "log" ? BinScale::logarithmic : BinScale::linear;
    if (!args->pdf_range.empty())
      options.density.range = parse_range(args->pdf_range, "--pdf-range");

    std::map<std::string, std::string> used;
    for (const auto& [key, value] : used_options(*cmd))
      used[key.substr(key.find('/') + 1)] = value;
    analyze_and_report(run, options, args->out, used);
  });
}

}  // namespace granmem::app
