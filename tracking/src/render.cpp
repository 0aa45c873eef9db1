#include "granmem/tracking/render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "granmem/core/error.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/tracking/partial_volume.hpp"
#include "seeded_random.hpp"

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Random streams, one per purpose and slice (or grain).
constexpr std::uint64_t kLightStream = 1;  // flicker and streaks of a slice
constexpr std::uint64_t kNoiseStream = 2;  // camera noise of a slice
constexpr std::uint64_t kAxisStream = 3;   // random cavity axis of a grain
constexpr double kBlockBytes = 512.0 * 1024 * 1024;

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

void require(bool ok, const std::string& what, double value) {
  if (!ok) throw Error("render: " + what + ", got " + text(value));
}

void check_grains(const std::vector<RenderedGrain>& grains) {
  for (const RenderedGrain& g : grains) {
    if (!g.centre.allFinite() || !std::isfinite(g.radius) || !(g.radius > 0)) {
      throw Error("render: grain " + std::to_string(g.id) +
                  " needs a finite centre and a positive radius");
    }
  }
}

// A sampled Gaussian, normalised to sum 1 (so that blurring keeps the mean); reach 4 sigma.
// The light is carried in double from here on: a float kernel sums to 1 only within ~1e-7
// per axis, and a float level (0.7f) can round a whole grain to the next grey value.
std::vector<double> gaussian_kernel(double sigma) {
  if (!(sigma > 0)) return {1.0f};
  const int reach = static_cast<int>(std::ceil(4 * sigma));
  std::vector<double> w(2 * reach + 1);
  double sum = 0;
  for (int k = -reach; k <= reach; ++k) {
    w[k + reach] = std::exp(-0.5 * k * k / (sigma * sigma));
    sum += w[k + reach];
  }
  for (double& v : w)
    v /= sum;
  return w;
}

// Length of [i - 1/2, i + 1/2] inside the wall's slab, for i = first, first + 1, ...
std::vector<double> wall_profile(const WallLine& wall, std::int64_t first, std::int64_t n) {
  std::vector<double> w(static_cast<std::size_t>(n));
  const double lo = wall.position - wall.thickness / 2, hi = wall.position + wall.thickness / 2;
  for (std::int64_t k = 0; k < n; ++k) {
    const double i = double(first + k);
    w[k] = std::max(0.0, std::min(hi, i + 0.5) - std::max(lo, i - 0.5));
  }
  return w;
}

// The padded stack: voxels beyond each border by the PSF's reach are drawn too, so that
// blurring needs no border rule and grains cut by the border blur as they would in a scan.
struct Layout {
  ScanGeometry geometry;
  std::int64_t px = 0, py = 0, pz = 0;  // padding (PSF reach) per axis
  std::int64_t nxp = 0, nyp = 0;        // padded slice size
  std::size_t slice_voxels() const { return static_cast<std::size_t>(nxp * nyp); }
};

struct Drawable {
  GrainShape shape;
  int levels = 0;
};

// Adds the tent-sampled grain fraction (cell_corner_shares) of each drawable in `ids` to
// the padded slices `layer` and `layer` + 1 (`below` and `above`, nyp x nxp; either may be
// null: not in the block), from the cells between them: cell (i, j) spans voxel centres
// i..i+1 along x and j..j+1 along y.
void draw_layer(const std::vector<Drawable>& drawables, const std::vector<std::int32_t>& ids,
                std::int64_t layer, const Layout& layout, float* below, float* above) {
  const ScanGeometry& g = layout.geometry;
  const Eigen::Vector3d v = g.voxel_size;
  const double z_lo = g.origin.z() + double(layer) * v.z();
  // Cells whose corners are all padded voxels or beyond.
  const std::int64_t i_first = -layout.px - 1, i_last = g.nx + layout.px - 1;
  const std::int64_t j_first = -layout.py - 1, j_last = g.ny + layout.py - 1;
  for (std::int32_t id : ids) {
    const GrainShape& s = drawables[id].shape;
    const int levels = drawables[id].levels;
    const double R = s.radius;
    const double dz = std::max({0.0, z_lo - s.centre.z(), s.centre.z() - (z_lo + v.z())});
    if (dz >= R) continue;
    const Eigen::Vector3d c = g.to_voxels(s.centre);
    const double ry = std::sqrt(R * R - dz * dz) / v.y();
    const std::int64_t j_lo = std::max<std::int64_t>(j_first, std::floor(c.y() - ry));
    const std::int64_t j_hi = std::min<std::int64_t>(j_last, std::ceil(c.y() + ry) - 1);
    for (std::int64_t j = j_lo; j <= j_hi; ++j) {
      const double y_lo = g.origin.y() + double(j) * v.y();
      const double dy = std::max({0.0, y_lo - s.centre.y(), s.centre.y() - (y_lo + v.y())});
      const double m2 = dy * dy + dz * dz;
      if (m2 >= R * R) continue;
      const double chord = std::sqrt(R * R - m2) / v.x();
      const std::int64_t i_lo = std::max<std::int64_t>(i_first, std::floor(c.x() - chord));
      const std::int64_t i_hi = std::min<std::int64_t>(i_last, std::ceil(c.x() + chord) - 1);
      for (std::int64_t i = i_lo; i <= i_hi; ++i) {
        const Eigen::Vector3d lo(g.origin.x() + double(i) * v.x(), y_lo, z_lo);
        const std::array<double, 8> shares = cell_corner_shares(s, lo, v, levels);
        for (int k = 0; k < 8; ++k) {
          float* plane = (k & 4) ? above : below;
          const std::int64_t x = i + (k & 1), y = j + ((k >> 1) & 1);
          if (plane == nullptr || x < -layout.px || x >= g.nx + layout.px || y < -layout.py ||
              y >= g.ny + layout.py) {
            continue;
          }
          plane[(y + layout.py) * layout.nxp + x + layout.px] += static_cast<float>(shares[k]);
        }
      }
    }
  }
}

// The light of slice z's sheet: its flicker factor and the profile across the beam of its
// streaks (1 where there are none), for the padded positions across the beam.
struct SheetLight {
  double flicker = 1;
  std::vector<double> across;
};

SheetLight sheet_light(const RenderOptions& o, std::int64_t z, std::int64_t first, std::int64_t n) {
  seeded_random::Stream random(o.seed, kLightStream, static_cast<std::uint64_t>(z));
  SheetLight light;
  light.flicker = std::max(0.0, 1 + o.flicker * random.normal());
  light.across.assign(static_cast<std::size_t>(n), 1.0);
  const std::int64_t streaks = random.poisson(o.streaks_per_slice);
  for (std::int64_t s = 0; s < streaks; ++s) {
    const double at = double(first) - 0.5 + random.uniform() * double(n);
    const double strength = o.streak_strength * random.uniform();
    const double reach = 5 * o.streak_width;
    const std::int64_t lo = std::max<std::int64_t>(0, std::floor(at - reach) - first);
    const std::int64_t hi = std::min<std::int64_t>(n - 1, std::ceil(at + reach) - first);
    for (std::int64_t k = lo; k <= hi; ++k) {
      const double d = (double(first + k) - at) / o.streak_width;
      light.across[k] += strength * std::exp(-0.5 * d * d);
    }
  }
  return light;
}

}  // namespace

void RenderOptions::validate() const {
  if (voxel_size) {
    for (int a = 0; a < 3; ++a) {
      require(std::isfinite((*voxel_size)[a]) && (*voxel_size)[a] > 0,
              "voxel size must be positive", (*voxel_size)[a]);
    }
  }
  require(std::isfinite(diameter_px) && diameter_px > 0, "diameter_px must be positive",
          diameter_px);
  require(std::isfinite(slice_spacing_ratio) && slice_spacing_ratio > 0,
          "slice_spacing_ratio must be positive", slice_spacing_ratio);
  if (origin) {
    for (int a = 0; a < 3; ++a)
      require(std::isfinite((*origin)[a]), "origin", (*origin)[a]);
  }
  if (size) {
    for (int a = 0; a < 3; ++a) {
      require((*size)[a] > 0, "stack size must be at least 1 voxel", double((*size)[a]));
    }
  }
  require(std::isfinite(margin) && margin >= 0, "margin must be >= 0 voxels", margin);
  require(hole_fraction >= 0 && hole_fraction < 1, "hole_fraction must be in [0, 1)",
          hole_fraction);
  require(std::isfinite(fluid()) && fluid() >= 0, "fluid level must be >= 0", fluid());
  require(std::isfinite(grain()) && grain() >= 0, "grain level must be >= 0", grain());
  require(edge_tolerance > 0, "edge_tolerance must be positive", edge_tolerance);
  for (int a = 0; a < 3; ++a) {
    require(std::isfinite(blur_sigma[a]) && blur_sigma[a] >= 0, "blur sigma must be >= 0",
            blur_sigma[a]);
  }
  require(std::isfinite(attenuation) && attenuation >= 0, "attenuation must be >= 0", attenuation);
  require(std::isfinite(flicker) && flicker >= 0, "flicker must be >= 0", flicker);
  require(std::isfinite(streaks_per_slice) && streaks_per_slice >= 0,
          "streaks_per_slice must be >= 0", streaks_per_slice);
  require(std::isfinite(streak_strength) && streak_strength >= 0, "streak_strength must be >= 0",
          streak_strength);
  require(std::isfinite(streak_width) && streak_width > 0, "streak_width must be positive",
          streak_width);
  if (wall) {
    require(wall->axis == 0 || wall->axis == 1, "wall axis must be 0 (x) or 1 (y)", wall->axis);
    require(std::isfinite(wall->position), "wall position must be finite", wall->position);
    require(std::isfinite(wall->thickness) && wall->thickness > 0,
            "wall thickness must be positive", wall->thickness);
    require(std::isfinite(wall->level) && wall->level >= 0, "wall level must be >= 0", wall->level);
  }
  require(std::isfinite(read_noise) && read_noise >= 0, "read_noise must be >= 0", read_noise);
  require(std::isfinite(gain) && gain >= 0, "gain must be >= 0", gain);
  require(bits == 8 || bits == 16, "bits must be 8 or 16", bits);
  require(slices_per_block >= 0, "slices_per_block must be >= 0", double(slices_per_block));
}

RenderOptions RenderOptions::without_artefacts() const {
  RenderOptions o = *this;
  o.blur_sigma.setZero();
  o.attenuation = 0;
  o.flicker = 0;
  o.streaks_per_slice = 0;
  o.wall.reset();
  o.read_noise = 0;
  o.gain = 0;
  return o;
}

double RenderOptions::fluid() const {
  if (fluid_level) return *fluid_level;
  return polarity == Polarity::dark_grains ? 0.75 : 0.1;
}

double RenderOptions::grain() const {
  if (grain_level) return *grain_level;
  return polarity == Polarity::dark_grains ? 0.15 : 0.7;
}

Eigen::Vector3d voxel_size_for(double median_radius, const RenderOptions& options) {
  const double pixel = 2 * median_radius / options.diameter_px;
  return Eigen::Vector3d(pixel, pixel, pixel * options.slice_spacing_ratio);
}

ScanGeometry scan_geometry(const std::vector<RenderedGrain>& grains, const RenderOptions& options) {
  options.validate();
  check_grains(grains);
  ScanGeometry g;
  if (options.voxel_size) {
    g.voxel_size = *options.voxel_size;
  } else {
    if (grains.empty()) throw Error("render: no grains to take the voxel size from; give one");
    std::vector<double> radii;
    for (const RenderedGrain& grain : grains)
      radii.push_back(grain.radius);
    g.voxel_size = voxel_size_for(median(radii), options);
  }
  if (options.origin && options.size) {
    g.origin = *options.origin;
  } else {
    if (grains.empty()) throw Error("render: no grains to take the stack's extent from");
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const RenderedGrain& grain : grains) {
      lo = lo.cwiseMin((grain.centre.array() - grain.radius).matrix());
      hi = hi.cwiseMax((grain.centre.array() + grain.radius).matrix());
    }
    lo -= options.margin * g.voxel_size;
    hi += options.margin * g.voxel_size;
    // Centred on the grains unless the origin is given.
    const Eigen::Vector3d counts = (hi - lo).cwiseQuotient(g.voxel_size);
    Eigen::Vector3d n;
    for (int a = 0; a < 3; ++a) {
      n[a] = options.size ? double((*options.size)[a]) : std::max(1.0, std::ceil(counts[a]));
    }
    g.origin = options.origin
                   ? *options.origin
                   : Eigen::Vector3d(0.5 * (lo + hi) -
                                     0.5 * (n.array() - 1).matrix().cwiseProduct(g.voxel_size));
    g.nx = std::int64_t(n.x());
    g.ny = std::int64_t(n.y());
    g.nz = std::int64_t(n.z());
  }
  if (options.size) {
    g.nx = (*options.size)[0];
    g.ny = (*options.size)[1];
    g.nz = (*options.size)[2];
  }
  return g;
}

Table render_truth(const std::vector<RenderedGrain>& grains, const ScanGeometry& geometry,
                   std::int64_t frame) {
  Table t;
  Column& frame_column = t.add("frame", "", true);
  Column& particle = t.add("particle", "", true);
  Column& x = t.add("x", "voxel");
  Column& y = t.add("y", "voxel");
  Column& z = t.add("z", "voxel");
  Column& radius = t.add("radius", "voxel");
  Column& ax = t.add("ax");
  Column& ay = t.add("ay");
  Column& az = t.add("az");
  Column& edge = t.add("edge", "", true);
  const Eigen::Vector3d n(double(geometry.nx), double(geometry.ny), double(geometry.nz));
  for (const RenderedGrain& g : grains) {
    const Eigen::Vector3d c = geometry.to_voxels(g.centre);
    const Eigen::Vector3d r =
        Eigen::Vector3d::Constant(g.radius).cwiseQuotient(geometry.voxel_size);
    // The stack spans [-1/2, n - 1/2] along each axis.
    const bool cut = ((c - r).array() < -0.5).any() || ((c + r).array() > n.array() - 0.5).any();
    frame_column.values.push_back(double(frame));
    particle.values.push_back(double(g.id));
    x.values.push_back(c.x());
    y.values.push_back(c.y());
    z.values.push_back(c.z());
    radius.values.push_back(r.x());
    const bool has_axis = g.axis.allFinite() && g.axis.norm() > 0;
    const Eigen::Vector3d a = has_axis ? g.axis.normalized() : Eigen::Vector3d::Constant(kNaN);
    ax.values.push_back(a.x());
    ay.values.push_back(a.y());
    az.values.push_back(a.z());
    edge.values.push_back(cut ? 1 : 0);
  }
  return t;
}

namespace {

// The blur kernels (x, y: the camera; z: the sheet's thickness) and the slices' padding,
// which is their reach.
struct Blur {
  std::vector<double> kx, ky, kz;
  explicit Blur(const Eigen::Vector3d& sigma)
      : kx(gaussian_kernel(sigma.x())),
        ky(gaussian_kernel(sigma.y())),
        kz(gaussian_kernel(sigma.z())) {}
};

Layout layout_of(const std::vector<RenderedGrain>& grains, const RenderOptions& options,
                 const Blur& blur) {
  Layout layout;
  layout.geometry = scan_geometry(grains, options);
  layout.px = std::int64_t(blur.kx.size() / 2);
  layout.py = std::int64_t(blur.ky.size() / 2);
  layout.pz = std::int64_t(blur.kz.size() / 2);
  layout.nxp = layout.geometry.nx + 2 * layout.px;
  layout.nyp = layout.geometry.ny + 2 * layout.py;
  return layout;
}

// Each grain's shape (its hole where the grains are dark and have an axis) and how finely
// its cells are refined.
std::vector<Drawable> drawables_of(const std::vector<RenderedGrain>& grains,
                                   const RenderOptions& options, const ScanGeometry& g) {
  std::vector<Drawable> drawables;
  for (const RenderedGrain& grain : grains) {
    Drawable d;
    d.shape.centre = grain.centre;
    d.shape.radius = grain.radius;
    const bool has_axis = grain.axis.allFinite() && grain.axis.norm() > 0;
    if (options.polarity == Polarity::dark_grains && has_axis && options.hole_fraction > 0) {
      d.shape.axis = grain.axis.normalized();
      d.shape.hole_radius = options.hole_fraction * grain.radius;
    }
    d.levels = refinement_levels(d.shape, g.voxel_size, options.edge_tolerance);
    drawables.push_back(d);
  }
  return drawables;
}

// The grains crossing each layer of cells: layer L lies between padded slices L and L + 1,
// for L = first() .. nz + pz - 1.
struct LayerIndex {
  std::int64_t first = 0;
  std::vector<std::vector<std::int32_t>> grains;
  const std::vector<std::int32_t>& at(std::int64_t layer) const {
    return grains[std::size_t(layer - first)];
  }
};

LayerIndex grains_by_layer(const std::vector<Drawable>& drawables, const Layout& layout) {
  const ScanGeometry& g = layout.geometry;
  LayerIndex index;
  index.first = -layout.pz - 1;
  const std::int64_t last = g.nz + layout.pz - 1;
  index.grains.resize(static_cast<std::size_t>(last - index.first + 1));
  for (std::size_t i = 0; i < drawables.size(); ++i) {
    const double c = g.to_voxels(drawables[i].shape.centre).z();
    const double r = drawables[i].shape.radius / g.voxel_size.z();
    const std::int64_t lo = std::max<std::int64_t>(index.first, std::floor(c - r));
    const std::int64_t hi = std::min<std::int64_t>(last, std::ceil(c + r) - 1);
    for (std::int64_t L = lo; L <= hi; ++L) {
      index.grains[L - index.first].push_back(static_cast<std::int32_t>(i));
    }
  }
  return index;
}

// The light of every slice but its flicker and streaks (sheet_light): the levels of grain
// and fluid, the wall seen edge-on, and the attenuation along the beam from the side where
// it enters (at -1/2 or n - 1/2), over the padded slice.
struct Illumination {
  double fluid = 0, grain = 0, wall_level = 0;
  std::vector<double> wall_x, wall_y;  // the wall's share of each column or row
  bool beam_along_x = true;
  std::vector<double> attenuation;  // per padded voxel along the beam
  std::int64_t across_first = 0, across_n = 0;

  Illumination(const RenderOptions& options, const Layout& layout)
      : fluid(options.fluid()),
        grain(options.grain()),
        wall_level(options.wall ? options.wall->level : 0.0),
        beam_along_x(options.beam == Beam::plus_x || options.beam == Beam::minus_x) {
    const ScanGeometry& g = layout.geometry;
    if (options.wall) {
      (options.wall->axis == 0 ? wall_x : wall_y) =
          options.wall->axis == 0 ? wall_profile(*options.wall, -layout.px, layout.nxp)
                                  : wall_profile(*options.wall, -layout.py, layout.nyp);
    }
    const std::int64_t along_n = beam_along_x ? layout.nxp : layout.nyp;
    const std::int64_t along_first = beam_along_x ? -layout.px : -layout.py;
    const std::int64_t along_count = beam_along_x ? g.nx : g.ny;
    attenuation.resize(static_cast<std::size_t>(along_n));
    for (std::int64_t k = 0; k < along_n; ++k) {
      const double i = double(along_first + k);
      const bool forward = options.beam == Beam::plus_x || options.beam == Beam::plus_y;
      const double travelled = forward ? i + 0.5 : double(along_count) - 0.5 - i;
      attenuation[k] = std::exp(-options.attenuation * travelled);
    }
    across_n = beam_along_x ? layout.nyp : layout.nxp;
    across_first = beam_along_x ? -layout.py : -layout.px;
  }
};

// Slices per block of the grain fraction held at once (with its halo of pz slices each side).
std::int64_t slices_per_block(const RenderOptions& options, const Layout& layout) {
  std::int64_t block = options.slices_per_block;
  if (block == 0) {
    const double fit = kBlockBytes / (double(layout.slice_voxels()) * sizeof(float));
    block = std::max<std::int64_t>(1, std::int64_t(fit) - 2 * layout.pz);
  }
  return std::min(block, layout.geometry.nz);
}

// The grain fraction of the padded slices first .. first + count - 1 into `phi`: the layers
// of cells from first - 1 to first + count - 1, even ones then odd ones; each writes two
// slices, which no other layer of its parity touches, so each slice adds its two layers in
// one order whatever the threads and blocks.
void draw_block(const std::vector<Drawable>& drawables, const LayerIndex& layers,
                const Layout& layout, std::int64_t first, std::int64_t count,
                std::vector<float>& phi) {
  const std::size_t plane = layout.slice_voxels();
  phi.assign(plane * static_cast<std::size_t>(count), 0.0f);
  const auto slice_phi = [&](std::int64_t z) -> float* {
    return z < first || z >= first + count
               ? nullptr
               : phi.data() + plane * static_cast<std::size_t>(z - first);
  };
  for (int parity = 0; parity < 2; ++parity) {
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t L = first - 1; L < first + count; ++L) {
      if (((L % 2) + 2) % 2 != parity) continue;
      draw_layer(drawables, layers.at(L), L, layout, slice_phi(L), slice_phi(L + 1));
    }
  }
}

// One slice from its block's grain fraction: emitted light (fluid + (grain - fluid) phi,
// the wall over it) gathered through the sheet's thickness (z PSF), the sheet's light, the
// camera (x, y PSF), its noise and quantisation.
class SliceRenderer {
 public:
  SliceRenderer(const RenderOptions& options, const Layout& layout, const Blur& blur,
                const Illumination& light)
      : o_(options), layout_(layout), blur_(blur), light_(light) {}

  void render(std::int64_t z, std::int64_t z0, const std::vector<float>& phi, Stack& stack) const {
    std::vector<double> sheet = emitted(z, z0, phi);
    illuminate(z, sheet);
    std::vector<double> image = camera(sheet);
    record(z, image, stack);
  }

 private:
  std::vector<double> emitted(std::int64_t z, std::int64_t z0,
                              const std::vector<float>& phi) const {
    const std::size_t plane = layout_.slice_voxels();
    std::vector<double> sheet(plane, 0.0);
    for (std::size_t k = 0; k < blur_.kz.size(); ++k) {
      const float* src = phi.data() + plane * static_cast<std::size_t>(z - z0 + k);
      for (std::int64_t y = 0; y < layout_.nyp; ++y) {
        const float* in = src + y * layout_.nxp;
        double* out = sheet.data() + y * layout_.nxp;
        for (std::int64_t x = 0; x < layout_.nxp; ++x) {
          // grain * f + fluid * (1 - f): exactly the grain's or the fluid's level at 1 or 0.
          const double f = std::min(double(in[x]), 1.0);
          double e = light_.grain * f + light_.fluid * (1 - f);
          if (!light_.wall_x.empty()) e += (light_.wall_level - e) * light_.wall_x[x];
          if (!light_.wall_y.empty()) e += (light_.wall_level - e) * light_.wall_y[y];
          out[x] += blur_.kz[k] * e;
        }
      }
    }
    return sheet;
  }

  void illuminate(std::int64_t z, std::vector<double>& sheet) const {
    const SheetLight light = sheet_light(o_, z, light_.across_first, light_.across_n);
    for (std::int64_t y = 0; y < layout_.nyp; ++y) {
      double* row = sheet.data() + y * layout_.nxp;
      if (light_.beam_along_x) {
        const double across = light.flicker * light.across[y];
        for (std::int64_t x = 0; x < layout_.nxp; ++x)
          row[x] *= across * light_.attenuation[x];
      } else {
        const double along = light.flicker * light_.attenuation[y];
        for (std::int64_t x = 0; x < layout_.nxp; ++x)
          row[x] *= along * light.across[x];
      }
    }
  }

  // Camera blur, x then y, onto the unpadded slice.
  std::vector<double> camera(const std::vector<double>& sheet) const {
    const ScanGeometry& g = layout_.geometry;
    std::vector<double> blurred_x(static_cast<std::size_t>(layout_.nyp * g.nx));
    for (std::int64_t y = 0; y < layout_.nyp; ++y) {
      const double* src = sheet.data() + y * layout_.nxp;
      double* dst = blurred_x.data() + y * g.nx;
      for (std::int64_t x = 0; x < g.nx; ++x) {
        double sum = 0;
        for (std::size_t k = 0; k < blur_.kx.size(); ++k)
          sum += blur_.kx[k] * src[x + std::int64_t(k)];
        dst[x] = sum;
      }
    }
    std::vector<double> image(static_cast<std::size_t>(g.ny * g.nx), 0.0);
    for (std::int64_t y = 0; y < g.ny; ++y) {
      double* dst = image.data() + y * g.nx;
      for (std::size_t k = 0; k < blur_.ky.size(); ++k) {
        const double* src = blurred_x.data() + (y + std::int64_t(k)) * g.nx;
        for (std::int64_t x = 0; x < g.nx; ++x)
          dst[x] += blur_.ky[k] * src[x];
      }
    }
    return image;
  }

  // Shot noise, read noise, quantisation (to the nearest grey value, halves up).
  void record(std::int64_t z, const std::vector<double>& image, Stack& stack) const {
    const double full_scale = stack.max_value();
    seeded_random::Stream random(o_.seed, kNoiseStream, static_cast<std::uint64_t>(z));
    std::uint16_t* out = stack.slice(z);
    for (std::size_t i = 0; i < image.size(); ++i) {
      double s = std::max(0.0, image[i]);
      if (o_.gain > 0) s = o_.gain * double(random.poisson(s / o_.gain));
      if (o_.read_noise > 0) s += o_.read_noise * random.normal();
      out[i] =
          static_cast<std::uint16_t>(std::clamp(std::floor(s * full_scale + 0.5), 0.0, full_scale));
    }
  }

  const RenderOptions& o_;
  const Layout& layout_;
  const Blur& blur_;
  const Illumination& light_;
};

}  // namespace

Stack render_scan(const std::vector<RenderedGrain>& grains, const RenderOptions& options,
                  Table* truth) {
  const Blur blur(options.blur_sigma);
  const Layout layout = layout_of(grains, options, blur);
  const ScanGeometry& g = layout.geometry;
  const std::vector<Drawable> drawables = drawables_of(grains, options, g);
  const LayerIndex layers = grains_by_layer(drawables, layout);
  const Illumination light(options, layout);
  const SliceRenderer slices(options, layout, blur, light);

  Stack stack(g.nx, g.ny, g.nz, options.bits);
  stack.voxel_size = g.voxel_size;
  stack.unit = options.length_unit;
  stack.source = "rendered scan (seed " + std::to_string(options.seed) + ")";
  const std::int64_t block = slices_per_block(options, layout);
  std::vector<float> phi;  // grain fraction of the padded slices of one block, with their halo
  for (std::int64_t z0 = 0; z0 < g.nz; z0 += block) {
    const std::int64_t z1 = std::min(g.nz, z0 + block);
    draw_block(drawables, layers, layout, z0 - layout.pz, z1 - z0 + 2 * layout.pz, phi);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t z = z0; z < z1; ++z)
      slices.render(z, z0, phi, stack);
  }
  if (truth) *truth = render_truth(grains, g, options.frame);
  return stack;
}

std::vector<RenderedGrain> rendered_grains(const Frame& frame, const RunHeader& header,
                                           std::uint64_t seed) {
  std::vector<RenderedGrain> grains;
  const std::size_t n = header.grain_count();
  if (std::size_t(frame.position.rows()) != n) {
    throw Error("render: frame " + std::to_string(frame.step) + " has " +
                std::to_string(frame.position.rows()) + " positions for " + std::to_string(n) +
                " grains");
  }
  const bool axes = header.has_axis && std::size_t(frame.axis.rows()) == n;
  const bool orientations = header.has_orientation && std::size_t(frame.orientation.rows()) == n;
  for (std::size_t i = 0; i < n; ++i) {
    const auto row = Eigen::Index(i);
    const Eigen::Vector3d x = frame.position.row(row).transpose();
    if (!x.allFinite()) continue;  // not seen in this frame
    RenderedGrain g;
    g.id = header.id[i];
    g.centre = x;
    g.radius = i < header.radius.size() ? header.radius[i] : kNaN;
    if (!std::isfinite(g.radius) || !(g.radius > 0)) {
      throw Error("render: grain " + std::to_string(g.id) +
                  " has no radius in the run; rendering needs one");
    }
    Eigen::Vector3d axis = Eigen::Vector3d::Constant(kNaN);
    if (axes) axis = frame.axis.row(row).transpose();
    if (!(axis.allFinite() && axis.norm() > 0) && orientations) {
      const auto q = frame.orientation.row(row);
      const Eigen::Quaterniond rotation(q(0), q(1), q(2), q(3));
      if (rotation.coeffs().allFinite() && rotation.norm() > 0) {
        axis = rotation.normalized() * Eigen::Vector3d::UnitZ();
      }
    }
    if (!(axis.allFinite() && axis.norm() > 0)) {
      seeded_random::Stream random(seed, kAxisStream, static_cast<std::uint64_t>(g.id));
      do {
        axis = normal_vector(random);  // the same on every compiler
      } while (!(axis.norm() > 1e-12));
    }
    g.axis = axis.normalized();
    grains.push_back(g);
  }
  return grains;
}

}  // namespace granmem
