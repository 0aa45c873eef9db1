#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/tracking/render_run.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem::app {
namespace {

// "a,b,c" -> numbers without units; between `least` and `most` of them.
std::vector<double> numbers(const std::string& text, const std::string& option, std::size_t least,
                            std::size_t most, const std::string& expected) {
  std::vector<double> values;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');) {
    const Quantity q = parse_quantity(item, option);
    if (!q.unit.empty() || !std::isfinite(q.value)) {
      throw Error(option + " '" + text + "': expected " + expected);
    }
    values.push_back(q.value);
  }
  if (values.size() < least || values.size() > most) {
    throw Error(option + " '" + text + "': expected " + expected);
  }
  return values;
}

// "X[,Y,Z][ unit]" -> the voxel size in the run's unit.
Beam beam_side(const std::string& text) {
  if (text == "+x") return Beam::plus_x;
  if (text == "-x") return Beam::minus_x;
  if (text == "+y") return Beam::plus_y;
  return Beam::minus_y;
}

}  // namespace

void add_render(CLI::App& app) {
  struct Args {
    std::string run, out, truth, voxel_size, polarity = "dark", beam = "+x", noise = "0.01,5e-4",
                                             streaks = "2,0.15,1.5", blur = "0.7,0.7,1", wall;
    std::int64_t frame = 0;
    double diameter_px = 12, slice_spacing_ratio = 1.5, margin = 4, hole_fraction = 0.3,
           attenuation = 3e-4, flicker = 0.02, edge_tolerance = 0.002;
    double fluid_level = NAN, grain_level = NAN;
    int bits = 8;
    bool no_artefacts = false;
    std::uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Draw a frame of a run as a synthetic laser-sheet scan (TIFF) and its truth");
  cmd->add_option("run", args->run, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--frame", args->frame, "the frame to draw (its step, as in the tables)")
      ->required();
  cmd->add_option("--out,-o", args->out, "TIFF stack to write")->required();
  cmd->add_option("--truth", args->truth,
                  "CSV to write: one row per grain, position and radius in voxels, axis, edge");
  cmd->add_option("--diameter-px", args->diameter_px,
                  "median grain diameter in pixels (sets the voxel size unless given)")
      ->capture_default_str();
  cmd->add_option("--voxel-size", args->voxel_size,
                  "voxel size X[,Y,Z] with a unit, e.g. 0.05,0.05,0.075mm (replaces "
                  "--diameter-px and --slice-spacing-ratio)");
  cmd->add_option("--slice-spacing-ratio", args->slice_spacing_ratio, "slice spacing / pixel size")
      ->capture_default_str();
  cmd->add_option("--margin", args->margin,
                  "voxels around the grains' extent (a run with a container: below its lower "
                  "corner, where every frame's stack starts, as a scanner's would)")
      ->capture_default_str();
  cmd->add_option("--bits", args->bits, "8 or 16")
      ->check(CLI::IsMember({8, 16}))
      ->capture_default_str();
  cmd->add_option("--polarity", args->polarity,
                  "dark: dark grains with bright holes in a bright fluid; bright: bright grains, "
                  "no hole seen, on a dark fluid")
      ->check(CLI::IsMember({"dark", "bright"}))
      ->capture_default_str();
  cmd->add_option("--hole-fraction", args->hole_fraction, "hole diameter / grain diameter")
      ->capture_default_str();
  cmd->add_option("--fluid-level", args->fluid_level,
                  "fluid brightness, fraction of full scale (default 0.75 dark, 0.1 bright)");
  cmd->add_option("--grain-level", args->grain_level,
                  "grain brightness, fraction of full scale (default 0.15 dark, 0.7 bright)");
  cmd->add_option("--edge-tolerance", args->edge_tolerance,
                  "largest shift of the drawn surfaces, voxels")
      ->capture_default_str();
  // The artefacts.
  std::vector<CLI::Option*> artefacts;
  artefacts.push_back(cmd->add_option("--noise", args->noise,
                                      "READ[,GAIN]: read noise sigma (fraction of full scale) and "
                                      "shot noise (gain per photoelectron); 0 turns one off")
                          ->capture_default_str());
  artefacts.push_back(cmd->add_option("--attenuation", args->attenuation,
                                      "light lost along the beam, per voxel: exp(-a s)")
                          ->capture_default_str());
  artefacts.push_back(
      cmd->add_option("--beam", args->beam, "where the sheet enters: +x, -x, +y or -y")
          ->check(CLI::IsMember({"+x", "-x", "+y", "-y"}))
          ->capture_default_str());
  artefacts.push_back(cmd->add_option("--flicker", args->flicker,
                                      "slice-to-slice sigma of the sheet's brightness (relative)")
                          ->capture_default_str());
  artefacts.push_back(cmd->add_option("--streaks", args->streaks,
                                      "PER_SLICE[,STRENGTH[,WIDTH]]: bright lines along the beam, "
                                      "mean number per slice, peak (fraction), sigma (voxels)")
                          ->capture_default_str());
  artefacts.push_back(cmd->add_option("--blur", args->blur,
                                      "Gaussian PSF sigma in voxels: S, or SX,SY,SZ (z: the "
                                      "sheet's thickness)")
                          ->capture_default_str());
  artefacts.push_back(cmd->add_option("--wall", args->wall,
                                      "AXIS,POSITION[,THICKNESS[,LEVEL]]: a container wall seen "
                                      "edge-on, x or y = POSITION (voxels)"));
  CLI::Option* no_artefacts = cmd->add_flag(
      "--no-artefacts", args->no_artefacts,
      "grains and quantisation only: no blur, attenuation, flicker, streaks, wall or noise");
  for (CLI::Option* o : artefacts)
    no_artefacts->excludes(o);
  cmd->add_option("--seed", args->seed, "random seed (noise, flicker, streaks, unknown axes)")
      ->capture_default_str();

  cmd->callback([args, cmd] {
    // Every option is checked, and the frame found, before anything is drawn or written.
    std::vector<NamedPath> outputs{{"--out", args->out}};
    if (!args->truth.empty()) outputs.push_back({"--truth", args->truth});
    check_outputs(outputs, {{"run", args->run}});
    RenderOptions o;
    o.diameter_px = args->diameter_px;
    o.slice_spacing_ratio = args->slice_spacing_ratio;
    o.margin = args->margin;
    o.bits = args->bits;
    o.polarity = args->polarity == "bright" ? Polarity::bright_grains : Polarity::dark_grains;
    o.hole_fraction = args->hole_fraction;
    if (!std::isnan(args->fluid_level)) o.fluid_level = args->fluid_level;
    if (!std::isnan(args->grain_level)) o.grain_level = args->grain_level;
    o.edge_tolerance = args->edge_tolerance;
    const std::vector<double> noise =
        numbers(args->noise, "--noise", 1, 2, "READ[,GAIN], plain numbers");
    o.read_noise = noise[0];
    o.gain = noise.size() > 1 ? noise[1] : 0.0;
    o.attenuation = args->attenuation;
    o.beam = beam_side(args->beam);
    o.flicker = args->flicker;
    const std::vector<double> streaks =
        numbers(args->streaks, "--streaks", 1, 3, "PER_SLICE[,STRENGTH[,WIDTH]], plain numbers");
    o.streaks_per_slice = streaks[0];
    if (streaks.size() > 1) o.streak_strength = streaks[1];
    if (streaks.size() > 2) o.streak_width = streaks[2];
    const std::vector<double> blur = numbers(args->blur, "--blur", 1, 3, "S or SX,SY,SZ in voxels");
    if (blur.size() == 2) throw Error("--blur '" + args->blur + "': expected S or SX,SY,SZ");
    o.blur_sigma = blur.size() == 1 ? Eigen::Vector3d::Constant(blur[0])
                                    : Eigen::Vector3d(blur[0], blur[1], blur[2]);
    if (!args->wall.empty()) {
      const std::size_t comma = args->wall.find(',');
      const std::string axis = args->wall.substr(0, comma);
      if ((axis != "x" && axis != "y") || comma == std::string::npos) {
        throw Error("--wall '" + args->wall +
                    "': expected x or y, then POSITION[,THICKNESS[,LEVEL]]");
      }
      const std::vector<double> w = numbers(args->wall.substr(comma + 1), "--wall", 1, 3,
                                            "x or y, then POSITION[,THICKNESS[,LEVEL]]");
      WallLine wall;
      wall.axis = axis == "x" ? 0 : 1;
      wall.position = w[0];
      if (w.size() > 1) wall.thickness = w[1];
      if (w.size() > 2) wall.level = w[2];
      o.wall = wall;
    }
    if (args->no_artefacts) o = o.without_artefacts();
    o.seed = args->seed;

    RenderRunOptions options;
    options.run = args->run;
    options.frame = args->frame;
    options.out = args->out;
    options.truth = args->truth;
    options.render = o;
    options.voxel_size = args->voxel_size;
    options.parameters = used_options(*cmd);
    std::cout << render_run(options).Report();
  });
}

}  // namespace granmem::app
