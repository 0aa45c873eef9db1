#include "granmem/tracking/locate.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>

#include "exact_radius.hpp"
#include "granmem/core/cell_grid.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/units.hpp"
#include "granmem/rotation/hole_contacts.hpp"
#include "granmem/tracking/candidates.hpp"
#include "granmem/tracking/grain_fit.hpp"
#include "granmem/tracking/hole_axis.hpp"
#include "granmem/tracking/illumination.hpp"

namespace granmem {
namespace {

// The hole's direction, roughly: the principal axis of the fluid seen inside the grain
// (within 0.75 R). Where the hole is seen bright (fluid >= 0.5: at 12 voxels and up), of
// those voxels, so that the blur's leak at the rim (wider along coarse slices) stays out;
// a small grain's hole, dimmed below that by the blur, from all the fluid in excess of its
// mean there (which takes out the grain's own level and the sampled ball's shape).
Eigen::Vector3d hole_direction(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<double>& fluid, const Eigen::Vector3d& centre,
                               double radius) {
  std::vector<std::size_t> inside;
  double mean = 0, bright = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    if ((points[k] - centre).norm() > 0.75 * radius) continue;
    inside.push_back(k);
    mean += fluid[k];
    if (fluid[k] >= 0.5) bright += fluid[k];
  }
  if (inside.size() < 10) return Eigen::Vector3d::UnitZ();
  mean /= double(inside.size());
  const bool seen_bright = bright >= 3;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t k : inside) {
    const double weight = seen_bright ? (fluid[k] >= 0.5 ? fluid[k] : 0.0) : fluid[k] - mean;
    const Eigen::Vector3d d = points[k] - centre;
    scatter += weight * d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  return eig.eigenvectors().col(2);
}

// A grain being located: where the candidates saw it, the fit to start the next pass
// from, the last fit, and whether it is (still) taken for a grain.
struct Candidate {
  Eigen::Vector3d found_at = Eigen::Vector3d::Zero();  // physical
  HoledSphere start;
  GrainFit fit;
  bool fitted = false, active = true;
};

// The voxels within the ellipsoid of semi-axes `reach` (x, y, z) around `centre` into
// `window`: their physical positions and fluid fractions.
void collect_window(const Stack& stack, const Eigen::Vector3d& centre, const Eigen::Vector3d& reach,
                    const Eigen::Vector3d& vs, GrainWindow& window) {
  const Eigen::Array3d last(double(stack.nx - 1), double(stack.ny - 1), double(stack.nz - 1));
  const Eigen::Vector3d lo = ((centre - reach).array() / vs.array()).ceil().max(0.0);
  const Eigen::Vector3d hi = ((centre + reach).array() / vs.array()).floor().min(last);
  window.points.clear();
  window.intensity.clear();
  window.clear.clear();
  for (auto z = std::int64_t(lo.z()); z <= std::int64_t(hi.z()); ++z) {
    for (auto y = std::int64_t(lo.y()); y <= std::int64_t(hi.y()); ++y) {
      for (auto x = std::int64_t(lo.x()); x <= std::int64_t(hi.x()); ++x) {
        const Eigen::Vector3d p = Eigen::Vector3d(double(x), double(y), double(z)).cwiseProduct(vs);
        if ((p - centre).cwiseQuotient(reach).squaredNorm() > 1) continue;
        window.points.push_back(p);
        window.intensity.push_back(fluid_fraction(stack.at(x, y, z)));
      }
    }
  }
}

// Leaves out of `window` the voxels the neighbours leave under 1e-3 clear (`clear`, one a
// voxel): they say nothing of this grain. Keeps the clear shares only `with_clear`.
void leave_out_hidden(const std::vector<double>& clear, bool with_clear, GrainWindow& window) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < clear.size(); ++k) {
    if (clear[k] < 1e-3) continue;
    window.points[kept] = window.points[k];
    window.intensity[kept] = window.intensity[k];
    if (with_clear) window.clear.push_back(clear[k]);
    ++kept;
  }
  window.points.resize(kept);
  window.intensity.resize(kept);
}

// Where a grain's hole runs along the slices (its axis within 11.5 deg of their plane), the
// model's profile of the hole's wall (a blurred plane's, HoledSphere) is not the image's:
// the wall, ~1.2 slices from the axis under a blur along z of about a slice, is a blurred
// cylinder's section sampled at the slices' spacing, and the product model fitted to it
// locks the centre to the slices (a sine of its place between two, 0.04-0.05 slice: 30 um
// on 5 mm grains; docs/BENCHMARKS.md, "Centres locked to the slices by a hole along
// them"). There the last centre refit leaves the hole and its wall (within the hole's
// radius plus 0.75 of the blur along z of the axis, inside the grain) out of its window
// (`clear` 0), and reads the centre off the grain's outer surface.
void leave_out_hole_wall_along_slices(const HoledSphere& grain, double hole, double blur_along_z,
                                      const GrainWindow& window, std::vector<double>& clear) {
  constexpr double kAlongSlices = 0.2, kWallBand = 0.75;  // |axis z|; of the blur along z
  const Eigen::Vector3d a = grain.axis.normalized();
  if (hole <= 0 || !(std::abs(a.z()) < kAlongSlices)) return;
  const double wall = hole * grain.radius + kWallBand * blur_along_z;
  const double inside = grain.radius + blur_along_z;
  for (std::size_t k = 0; k < window.points.size(); ++k) {
    const Eigen::Vector3d d = window.points[k] - grain.centre;
    if ((d - d.dot(a) * a).norm() < wall && d.norm() < inside) clear[k] = 0;
  }
}

// `grain`'s fraction M at each voxel of `window` within `reach` of its centre, passed on
// as combine(voxel, M), lanes of voxels at a time.
template <class Combine>
void grain_fraction_near(const HoledSphere& grain, double reach, const GrainWindow& window,
                         const Combine& combine) {
  FractionsInTurn<std::size_t, const Combine&> in_turn(grain, combine);
  for (std::size_t k = 0; k < window.points.size(); ++k) {
    if ((window.points[k] - grain.centre).norm() < reach) in_turn.add(window.points[k], k);
  }
  in_turn.finish();
}

// The voxels within `reach` (x, y, z) of grain `s`: with `model_neighbours`, each with how much of
// it the neighbours leave clear, prod (1 - M_neighbour); without, only the voxels nearer this grain
// than any neighbour.
void window_of(const Stack& stack, const HoledSphere& s, const Eigen::Vector3d& reach,
               const std::vector<const HoledSphere*>& near, bool model_neighbours,
               const Eigen::Vector3d& vs, GrainWindow& window) {
  collect_window(stack, s.centre, reach, vs, window);
  std::vector<double> clear(window.points.size(), 1.0);
  if (model_neighbours) {
    for (const HoledSphere* other : near) {
      const double other_reach = other->radius + 4 * other->widest_blur();
      // None of the window's voxels within its reach (with a margin for the roundings of
      // the distances): not one to look at.
      const double meets = (other_reach + reach.maxCoeff()) * (1 + 1e-9);
      if (!((other->centre - s.centre).norm() < meets)) continue;
      grain_fraction_near(*other, other_reach, window,
                          [&](std::size_t k, double m) { clear[k] *= 1 - m; });
    }
  } else {
    for (std::size_t k = 0; k < clear.size(); ++k) {
      const double d = (window.points[k] - s.centre).norm();
      for (const HoledSphere* other : near) {
        if ((window.points[k] - other->centre).norm() < d) {
          clear[k] = 0;  // theirs
          break;
        }
      }
    }
  }
  leave_out_hidden(clear, model_neighbours, window);
}

// The voxels within `reach` of `centre`, each with what the neighbours leave clear, 1 -
// the sum of their grain fractions there, which add_others(window, sum) adds to `sum`.
template <class AddOthers>
void inner_window(const Stack& stack, const Eigen::Vector3d& centre, double reach,
                  const AddOthers& add_others, const Eigen::Vector3d& vs, GrainWindow& window) {
  collect_window(stack, centre, Eigen::Vector3d::Constant(reach), vs, window);
  std::vector<double> clear(window.points.size(), 0.0);
  add_others(window, clear);  // the neighbours' grain fractions, then what they leave clear
  for (double& c : clear)
    c = 1 - c;
  leave_out_hidden(clear, true, window);
}

}  // namespace

void LocateOptions::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error("locate: " + what);
  };
  require(std::isfinite(diameter) && diameter > 0, "the grain diameter must be positive");
  require(hole_fraction >= 0 && hole_fraction <= 0.8, "hole_fraction must be in [0, 0.8]");
  require(beam_axis == 0 || beam_axis == 1, "the beam runs along x (0) or y (1)");
  require(max_axis_sigma_degrees > 0, "max_axis_sigma_degrees must be positive");
  require(min_contrast >= 0 && min_contrast < 1, "min_contrast must be in [0, 1)");
  require(radius_tolerance > 0 && radius_tolerance < 1, "radius_tolerance must be in (0, 1)");
  require(passes >= 1 && passes <= 10, "passes must be 1 to 10");
  require(search_rounds >= 0, "search_rounds must be 0 or more");
}

namespace {

// The grains of one normalised scan being located, stage by stage: candidates, model fits
// pass after pass with searches for missed grains between them, the holes' axes, and the
// detections. Lengths physical (voxels where the scan has no voxel size).
// Between two stages: stops if asked (an Error the caller sees as the interruption), else
// says what comes next.
void begin_stage(const LocateOptions& o, const std::string& what) {
  if (o.stop && o.stop->load()) throw Error("locate: stopped before " + what);
  if (o.log) o.log(what);
}

class GrainLocator {
 public:
  GrainLocator(const Stack& stack, const LocateOptions& o)
      : stack_(stack),
        o_(o),
        vs_(stack.voxel_size.value_or(Eigen::Vector3d::Ones())),
        diameter_(o.diameter * vs_.x()),
        radius_(0.5 * diameter_),
        hole_(o.dark_grains ? o.hole_fraction : 0.0) {
    candidate_options_.diameter = diameter_voxels(o, vs_);
  }

  // The candidates of the scan (maxima of the smoothed grain fraction).
  void find() { add_candidates(find_candidates(stack_, candidate_options_)); }

  // The next stage begins: said, unless the caller has asked to stop.
  void stage(const std::string& what) const { begin_stage(o_, what); }

  // A first fit of every candidate with its neighbours' voxels left out, then, with the
  // neighbours in the model, pass after pass; before each, grains the candidates missed
  // (a maximum merged with a neighbour's, a fit drawn onto a neighbour) are looked for in
  // what the found grains leave unexplained, so that no fit is pulled into an unexplained
  // grain. Each fit reads its neighbours as the last pass left them: `passes` refit every
  // grain; further searches only the new grains and their neighbours.
  void fit() {
    stage("fits: the first pass over " + std::to_string(grains_.size()) + " candidates");
    fit_pass(false, [](std::size_t) { return true; });
    select();
    const int rounds = std::max(o_.passes - 1, o_.search_rounds);
    for (int round = 0; round < rounds; ++round) {
      stage("fits: round " + std::to_string(round + 2) + " of up to " + std::to_string(rounds + 1) +
            ", " + std::to_string(grains_.size()) + " grains");
      const std::vector<Eigen::Vector3d> hidden =
          round < o_.search_rounds ? search_unexplained() : std::vector<Eigen::Vector3d>{};
      const bool refit_all = round < o_.passes - 1;
      if (hidden.empty() && !refit_all) break;
      const std::size_t first_new = grains_.size();
      add_candidates(hidden);
      const auto is_new = [&](std::size_t i) { return i >= first_new; };
      fit_pass(true, is_new);
      const auto near_new = reaching_new(first_new);
      fit_pass(true, [&](std::size_t i) { return refit_all || near_new(i); });
      select();
    }
  }

  // The hole's axis, refitted on each grain's inner voxels with a blur of its own across
  // and along z (hole_axis.hpp): the model fits' axes tilt on scans of coarser slices. The
  // neighbours' grain fractions are added to the model's (the blur is linear, the grains
  // do not overlap). Seen through the model fits' profiles, with their radius that runs
  // small there, they tilt the axes by a degree where the blur along z is wide; so first a
  // sample of the grains is refitted with them so, for the scan's blur (the medians of the
  // refits') and the model fits' radius shortfall (the median of refit - model fit
  // radius), and then every grain with its neighbours seen through that blur, their radius
  // so corrected; last, a sample's whole windows give the radius the exactly blurred image
  // has for a model fit's (exact_radius.hpp), the radius every grain is drawn and reported
  // with from then on.
  void refit_axes() {
    if (hole_ == 0 || !o_.fit_axis) return;
    const Neighbours known = neighbours(true);
    HoleAxisOptions axis_options;
    const std::size_t stride = std::max<std::size_t>(1, known.ids.size() / 64);
    std::vector<HoleAxisFit> refits(known.ids.size());
    AxisBlur blur;
    refit_axes(known, stride, blur, axis_options, refits);
    if (sample_blur(known.ids, refits, stride, &blur, &axis_options)) {
      refit_axes(known, 1, blur, axis_options, refits);
      // 24 grains: a line's two parameters, through exact radii that scatter by 3 um;
      // whole windows are ~8x the inner ones.
      const std::size_t every = std::max<std::size_t>(1, known.ids.size() / 24);
      blur.radius = exact_radius(known, every, blur, axis_options);
      blur_ = blur;
    }
    for (std::size_t k = 0; k < known.ids.size(); ++k) {
      const HoleAxisFit& r = refits[k];
      GrainFit& f = grains_[known.ids[k]].fit;
      if (r.converged && std::isfinite(r.sigma)) {
        f.sphere.axis = r.axis;
        f.axis_sigma = r.sigma;
      }
    }
  }

  // A last model fit of every grain's centre with its neighbours seen as the scan draws
  // them: through the exactly blurred image at the scan's blur, their radius corrected,
  // their grain fractions added to the grain's own.
  void refit_centres() {
    if (!blur_.sampled) return;
    const Neighbours known = neighbours(true);
    std::vector<GrainFit> fits(known.ids.size());
    const double wide = std::max(blur_.across, blur_.along_z);
#pragma omp parallel
    {
      GrainWindow window;
      std::vector<HoledSphere> near;
#pragma omp for schedule(dynamic, 16)
      for (std::size_t k = 0; k < known.ids.size(); ++k) {
        const HoledSphere& s = grains_[known.ids[k]].fit.sphere;
        const Eigen::Vector3d reach = window_reach(s);
        near.clear();
        known.grid.near(s.centre, 2, [&](std::size_t j) {
          HoledSphere other = grains_[known.ids[j]].fit.sphere;
          other.radius = blur_.radius(other.radius);
          if (j != k &&
              (other.centre - s.centre).norm() < reach.maxCoeff() + other.radius + 5 * wide)
            near.push_back(other);
        });
        collect_window(stack_, s.centre, reach, vs_, window);
        std::vector<double> sum(window.points.size(), 0.0);
        for (const HoledSphere& other : near)
          add_blurred_grain_fraction(window.points, other.radius + 5 * wide, other, blur_.across,
                                     blur_.along_z, sum);
        for (double& c : sum)
          c = 1 - c;
        leave_out_hole_wall_along_slices(s, hole_, blur_.along_z, window, sum);
        leave_out_hidden(sum, true, window);
        window.additive = true;
        if (window.points.size() <= 20) continue;
        GrainFitOptions fo;
        fo.fit_axis = false;  // the refit's axis stands
        fits[k] = fit_grain(window, s, fo);
      }
    }
    for (std::size_t k = 0; k < known.ids.size(); ++k) {
      GrainFit& f = grains_[known.ids[k]].fit;
      const GrainFit& r = fits[k];
      if (!shaped_like_a_grain(r) ||
          (r.sphere.centre - f.sphere.centre).norm() > 0.5 * vs_.minCoeff())
        continue;
      // The centre only: the radius, which the exact refits' line predicts from these fits,
      // and the refit's axis stand.
      f.sphere.centre = r.sphere.centre;
      f.centre_sigma = r.centre_sigma;
    }
  }

  // The grains taken, with their quality, edge flags, axes and hole contacts.
  Detections detections(LocateSummary& sum) const {
    sum.candidates = grains_.size();
    Detections d;
    d.has_axis = hole_ > 0;
    d.source = stack_.source;
    d.length_unit = stack_.voxel_size ? stack_.unit : "voxel";
    d.voxel_size = stack_.voxel_size;
    const Eigen::Vector3d dims(double(stack_.nx), double(stack_.ny), double(stack_.nz));
    std::vector<double> contact_radius;
    constexpr double kDegree = 3.14159265358979323846 / 180;
    for (const Candidate& g : grains_) {
      if (!g.active) continue;
      const GrainFit& f = g.fit;
      const Eigen::Vector3d voxel = f.sphere.centre.cwiseQuotient(vs_);
      // The model fit's radius runs small (the blur's curvature shift, 0.35 voxel at 12
      // voxels): the exactly blurred image's (with a hole), as the refits' line predicts it;
      // for the edge flags, not below the nominal either.
      const double radius = blur_.radius(f.sphere.radius);
      const double outer = std::max(radius, radius_);
      const Eigen::Vector3d r_voxels = Eigen::Vector3d::Constant(outer).cwiseQuotient(vs_);
      const bool edge = ((voxel - r_voxels).array() < -0.5).any() ||
                        ((voxel + r_voxels).array() > dims.array() - 0.5).any();
      sum.on_edge += edge;
      contact_radius.push_back(outer);
      // Physical units when the voxel size is known, voxels otherwise (vs = 1 then).
      d.add(f.sphere.centre, radius, quality(f), edge);
      const std::size_t row = d.size() - 1;
      d.position_error.row(Eigen::Index(row)) = f.centre_sigma.transpose();
      if (!d.has_axis || edge) continue;  // a cut grain's hole may be cut too: no axis
      if (o_.fit_axis) {
        // Seen when the fit pins it down: its standard error under the limit.
        if (!(f.axis_sigma <= o_.max_axis_sigma_degrees * kDegree)) continue;
        d.axis.row(Eigen::Index(row)) = f.sphere.axis.transpose();
        d.axis_quality[row] = 1 / (1 + f.axis_sigma / kDegree);
        d.axis_error[row] = f.axis_sigma;
      } else {
        d.axis.row(Eigen::Index(row)) =
            lab_hole_axis(stack_, f.sphere.centre, radius_, vs_).transpose();
      }
    }
    if (d.has_axis) {
      HoleContactOptions contacts;
      contacts.hole_fraction = hole_;
      d.hole_contact = hole_contacts(d.position, contact_radius, d.axis, contacts);
    }
    sum.rejected = sum.candidates - d.size();
    sum.located = d.size();
    return d;
  }

 private:
  // The active grains (only those fitted, with `fitted_only`) and a grid to find them by.
  struct Neighbours {
    std::vector<std::size_t> ids;
    CellGrid grid;
  };
  // The scan's blur, from a sample of axis refits, and the radius a grain is drawn at for
  // its model fit's: the model fit's (without refits), plus the sample's median shortfall
  // (the inner refits), then the whole windows' exact radius (exact_radius()).
  struct AxisBlur {
    double across = 0, along_z = 0;
    ExactRadius radius;
    bool sampled = false;
  };

  static Eigen::Vector3d diameter_voxels(const LocateOptions& o, const Eigen::Vector3d& vs) {
    return Eigen::Vector3d::Constant(o.diameter * vs.x()).cwiseQuotient(vs);
  }

  // How well a fit explains its voxels: 1 - rms / contrast, in [0, 1].
  static double quality(const GrainFit& f) {
    const double contrast = f.fluid - f.grain;
    return contrast > 0 ? std::clamp(1 - f.rms / contrast, 0.0, 1.0) : 0.0;
  }

  void add_candidates(const std::vector<Eigen::Vector3d>& found_at) {
    for (const Eigen::Vector3d& c : found_at) {
      Candidate g;
      g.found_at = c.cwiseProduct(vs_);
      g.start.centre = g.found_at;
      g.start.radius = radius_;
      g.start.blur = 0.6 * vs_.x();
      g.start.blur_z = 0.6 * vs_.z();
      g.start.hole = hole_;
      grains_.push_back(g);
    }
  }

  // Candidates in what the grains found so far leave unexplained, but where a fit found
  // less contrast than a grain has: the dark blur of a small pore between grains, say,
  // which would be found again and again and hide the grains around it.
  std::vector<Eigen::Vector3d> search_unexplained() const {
    std::vector<HoledSphere> found;
    std::vector<Eigen::Vector3d> tried;
    for (const Candidate& g : grains_) {
      if (g.active) {
        found.push_back(g.start);
      } else if (g.fitted && g.fit.fluid - g.fit.grain < o_.min_contrast) {
        tried.push_back(g.found_at);
      }
    }
    return find_candidates(stack_, candidate_options_, &found, vs_, &tried);
  }

  // Whether grain i's window reaches one of the grains from `first_new` on.
  std::function<bool(std::size_t)> reaching_new(std::size_t first_new) const {
    auto centres = std::make_shared<std::vector<Eigen::Vector3d>>();
    for (std::size_t i = first_new; i < grains_.size(); ++i)
      centres->push_back(grains_[i].start.centre);
    auto grid = std::make_shared<CellGrid>(*centres, diameter_);
    return [this, centres, grid, first_new](std::size_t i) {
      bool near = i >= first_new;
      grid->near(grains_[i].start.centre, 2, [&](std::size_t k) {
        near |= ((*centres)[k] - grains_[i].start.centre).norm() < 2 * diameter_;
      });
      return near;
    };
  }

  // A converged fit of the nominal size and blurs under the radius: a blur that wide
  // smears a grain into its neighbours, and such a fit explains something else (its next
  // window, three blurs wide, would be huge). Only such fits are started from again.
  bool shaped_like_a_grain(const GrainFit& f) const {
    return f.converged && f.sphere.centre.allFinite() &&
           std::abs(f.sphere.radius / radius_ - 1) <= o_.radius_tolerance &&
           f.sphere.widest_blur() < radius_;
  }

  Neighbours neighbours(bool fitted_only) const {
    std::vector<Eigen::Vector3d> centres;
    std::vector<std::size_t> ids;
    for (std::size_t i = 0; i < grains_.size(); ++i) {
      if (grains_[i].active && (grains_[i].fitted || !fitted_only)) {
        centres.push_back(grains_[i].start.centre);
        ids.push_back(i);
      }
    }
    return Neighbours{std::move(ids), CellGrid(centres, diameter_)};
  }

  // A model fit's window around `s`: three blurs beyond the radius, across the slices and
  // along z.
  Eigen::Vector3d window_reach(const HoledSphere& s) const {
    const double margin = s.radius + 0.5 * vs_.maxCoeff();
    return {margin + 3 * s.blur, margin + 3 * s.blur, margin + 3 * s.along_z()};
  }

  // One fit of grain i: with the voxels nearer another grain left out or, once the
  // neighbours are known, with them in the model.
  GrainFit fit_one(std::size_t i, bool model_neighbours, const Neighbours& known,
                   GrainWindow& window, std::vector<const HoledSphere*>& near) const {
    const HoledSphere& s = grains_[i].start;
    const Eigen::Vector3d reach = window_reach(s);
    near.clear();
    known.grid.near(s.centre, 2, [&](std::size_t k) {
      const HoledSphere& other = grains_[known.ids[k]].start;
      if (known.ids[k] != i && (other.centre - s.centre).norm() < 2 * reach.maxCoeff() + radius_) {
        near.push_back(&other);
      }
    });
    window_of(stack_, s, reach, near, model_neighbours, vs_, window);
    if (window.points.size() <= 20) return {};
    HoledSphere from = s;
    GrainFitOptions fo;
    fo.fit_axis = o_.fit_axis;
    if (!grains_[i].fitted && hole_ > 0) {
      // The hole's direction is read from the fluid inside the grain, which needs the
      // centre first: a sphere without hole fitted from the candidate gives it.
      HoledSphere plain = s;
      plain.hole = 0;
      GrainFitOptions start = fo;
      start.standard_errors = false;
      const GrainFit sphere = fit_grain(window, plain, start);
      if (sphere.converged && (sphere.sphere.centre - s.centre).norm() < 0.5 * s.radius) {
        from.centre = sphere.sphere.centre;
      }
      from.axis = hole_direction(window.points, window.intensity, from.centre, s.radius);
    }
    return fit_grain(window, from, fo);
  }

  // One fit of every active grain that `refit` selects. Each reads its neighbours as the
  // last pass left them, so the order of the fits does not matter.
  template <class Refit>
  void fit_pass(bool model_neighbours, const Refit& refit) {
    const Neighbours known = neighbours(model_neighbours);
    std::vector<GrainFit> fits(grains_.size());
#pragma omp parallel
    {
      GrainWindow window;
      std::vector<const HoledSphere*> near;
#pragma omp for schedule(dynamic, 16)
      for (std::size_t i = 0; i < grains_.size(); ++i) {
        if (grains_[i].active && refit(i)) {
          fits[i] = fit_one(i, model_neighbours, known, window, near);
        }
      }
    }
    for (std::size_t i = 0; i < grains_.size(); ++i) {
      if (!grains_[i].active || !refit(i)) continue;
      Candidate& g = grains_[i];
      g.fit = fits[i];
      g.fitted = true;
      if (shaped_like_a_grain(g.fit)) g.start = g.fit.sphere;
    }
  }

  // Keeps the fits that look like grains; of two that found the same grain, the better.
  void select() {
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < grains_.size(); ++i)
      if (grains_[i].active) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return quality(grains_[a].fit) > quality(grains_[b].fit);
    });
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t i : order) {
      const GrainFit& f = grains_[i].fit;
      const bool grain_like = shaped_like_a_grain(f) && f.fluid - f.grain >= o_.min_contrast &&
                              (f.sphere.centre - grains_[i].found_at).norm() < diameter_;
      const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const auto& c) {
        return (c - f.sphere.centre).norm() < 0.5 * diameter_;
      });
      grains_[i].active = grain_like && !duplicate;
      if (grains_[i].active) kept.push_back(f.sphere.centre);
    }
  }

  // Refits the axes of every `step`-th grain, the neighbours seen through the model fits'
  // blur (before the sample) or through `blur` (after it).
  // `rings`: of the neighbours' grid cells (a diameter wide) searched around each grain,
  // enough for its window's reach plus a neighbour's radius and blurred rim.
  void refit_axes(const Neighbours& known, std::size_t step, const AxisBlur& blur,
                  const HoleAxisOptions& axis_options, std::vector<HoleAxisFit>& refits,
                  int rings = 1) const {
    const std::vector<std::size_t>& ids = known.ids;
#pragma omp parallel
    {
      GrainWindow window;
      std::vector<HoledSphere> near;  // the neighbours as this round sees them
#pragma omp for schedule(dynamic, 4)
      for (std::size_t k = 0; k < ids.size(); k += step) {
        const GrainFit& f = grains_[ids[k]].fit;
        // Within the refit's radius (the model fit's runs small): ~1 voxel more of the
        // hole at PSF 1.0 / 1.0 / 1.5 voxel (p95 2.96 -> 2.80 deg at d = 12).
        const double reach = axis_options.within * blur.radius(f.sphere.radius);
        const double wide = std::max(blur.across, blur.along_z);
        near.clear();
        known.grid.near(f.sphere.centre, rings, [&](std::size_t j) {
          HoledSphere s = grains_[ids[j]].start;
          s.radius = blur.radius(s.radius);
          const double reach_j = s.radius + 5 * (blur.sampled ? wide : s.widest_blur());
          if (j != k && (s.centre - f.sphere.centre).norm() < reach + reach_j) near.push_back(s);
        });
        const auto others = [&](const GrainWindow& w, std::vector<double>& sum) {
          for (const HoledSphere& s : near) {
            if (!blur.sampled) {
              grain_fraction_near(s, s.radius + 4 * s.widest_blur(), w,
                                  [&](std::size_t k, double m) { sum[k] += m; });
              continue;
            }
            add_blurred_grain_fraction(w.points, s.radius + 5 * wide, s, blur.across, blur.along_z,
                                       sum);
          }
        };
        inner_window(stack_, f.sphere.centre, reach, others, vs_, window);
        refits[k] = fit_hole_axis(window, f, axis_options);
      }
    }
  }

  // The exactly blurred image's radius for a model fit's: the line through the sample's
  // radii refitted on it in the whole window (the rim and three blurs beyond it; the axis
  // refits' inner voxels see the radius only through the hole, whose partial volumes bias
  // it on sharp scans) against their model fits'.
  ExactRadius exact_radius(const Neighbours& known, std::size_t stride, const AxisBlur& blur,
                           HoleAxisOptions whole) const {
    const double wide = std::max(blur.across, blur.along_z);
    whole.within = 1 + (3 * wide + 0.5 * vs_.maxCoeff()) / radius_;
    const double reach = whole.within * radius_ + radius_ + 5 * wide;
    std::vector<HoleAxisFit> refits(known.ids.size());
    // Twice: the second time the sample's neighbours are drawn at the first line's radius
    // instead of the inner refits' shortfall (the line's own then, +1.3 um at 12 voxels).
    AxisBlur seen = blur;
    for (int pass = 0; pass < 2; ++pass) {
      refit_axes(known, stride, seen, whole, refits, int(std::ceil(reach / diameter_)));
      std::vector<double> model, exact;
      for (std::size_t k = 0; k < known.ids.size(); k += stride) {
        if (!refits[k].converged) continue;
        model.push_back(grains_[known.ids[k]].fit.sphere.radius);
        exact.push_back(refits[k].radius);
      }
      if (exact.empty()) break;
      seen.radius = fit_exact_radius(model, exact);
    }
    return seen.radius;
  }

  // The scan's blur and the radius shortfall, the medians of the sample's converged
  // refits; every grain's refit starts there (fewer iterations than from the model fit).
  // False when none converged: the sample's refits stand.
  bool sample_blur(const std::vector<std::size_t>& ids, const std::vector<HoleAxisFit>& refits,
                   std::size_t stride, AxisBlur* blur, HoleAxisOptions* axis_options) const {
    std::vector<double> a, z, r, b, g;
    for (std::size_t k = 0; k < ids.size(); k += stride) {
      if (!refits[k].converged) continue;
      const GrainFit& f = grains_[ids[k]].fit;
      a.push_back(refits[k].blur_across);
      z.push_back(refits[k].blur_along_z);
      r.push_back(refits[k].radius - f.sphere.radius);
      b.push_back(refits[k].fluid - f.fluid);
      g.push_back(refits[k].grain - f.grain);
    }
    if (a.empty()) return false;
    const auto median = [](std::vector<double>& v) { return quantile_in_place(v, 0.5); };
    blur->across = median(a);
    blur->along_z = median(z);
    blur->radius = {median(r), 1};
    blur->sampled = true;
    axis_options->start = {blur->across, blur->along_z, blur->radius.intercept, median(b),
                           median(g)};
    return true;
  }

  const Stack& stack_;
  const LocateOptions& o_;
  const Eigen::Vector3d vs_;
  const double diameter_, radius_, hole_;
  // The scan's blur and the exact radius of a model fit's (exact_radius()), as refit_axes()
  // sampled them; not sampled (the model fit's radius) without refits.
  AxisBlur blur_;
  CandidateOptions candidate_options_;
  std::vector<Candidate> grains_;
};

// The grain diameter fits in the stack.
void check_fits(const Stack& stack, const LocateOptions& o) {
  const Eigen::Vector3d vs = stack.voxel_size.value_or(Eigen::Vector3d::Ones());
  const Eigen::Vector3d dims(double(stack.nx), double(stack.ny), double(stack.nz));
  const Eigen::Vector3d diameter = Eigen::Vector3d::Constant(o.diameter * vs.x()).cwiseQuotient(vs);
  if ((diameter.array() > dims.array()).any()) {
    const std::string& where = stack.source.empty() ? std::string("stack") : stack.source;
    throw Error(where + ": grain diameter " + std::to_string(o.diameter) +
                " voxels is larger than the stack (" + std::to_string(stack.nx) + " x " +
                std::to_string(stack.ny) + " x " + std::to_string(stack.nz) + ")");
  }
}

// The scan's levels made fluid 1, grain 0 (illumination.hpp).
void normalize(Stack& stack, const LocateOptions& o) {
  const Eigen::Vector3d vs = stack.voxel_size.value_or(Eigen::Vector3d::Ones());
  IlluminationOptions light;
  light.diameter = o.diameter * vs.x() / vs[o.beam_axis];
  light.dark_grains = o.dark_grains;
  light.beam_axis = o.beam_axis;
  if (o.correct_illumination) {
    normalize_illumination(stack, light);
  } else {
    normalize_levels(stack, light);
  }
}

}  // namespace

Detections locate(Stack stack, const LocateOptions& o, LocateSummary* summary) {
  o.validate();
  check_fits(stack, o);
  auto clock = std::chrono::steady_clock::now();
  auto lap = [&clock] {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - clock).count();
    clock = now;
    return s;
  };
  LocateSummary sum;
  begin_stage(o, "illumination");
  normalize(stack, o);
  sum.seconds_illumination = lap();
  GrainLocator locator(stack, o);
  begin_stage(o, "candidates");
  locator.find();
  sum.seconds_candidates = lap();
  locator.fit();
  begin_stage(o, "hole axes");
  locator.refit_axes();
  // Twice: the first refit sees each neighbour where the model fits left it, pulled
  // towards its own neighbours (their product reads shared rims too bright), and pushes the
  // grain away from it; the second sees the first's centres (docs/BENCHMARKS.md, "The
  // neighbours at the exact refits' radius, and where the first refit left them").
  for (int pass = 0; pass < 2; ++pass)
    locator.refit_centres();
  sum.seconds_fits = lap();
  Detections d = locator.detections(sum);
  sum.seconds = sum.seconds_illumination + sum.seconds_candidates + sum.seconds_fits + lap();
  if (summary) *summary = sum;
  return d;
}

namespace {

bool in_voxels(const Quantity& diameter) {
  const std::string& u = diameter.unit;
  return u.empty() || u == "vox" || u == "voxel" || u == "px";
}

}  // namespace

void check_diameter(const std::string& text, const std::string& what) {
  const Quantity q = parse_quantity(text, what);
  if (!std::isfinite(q.value) || !(q.value > 0)) {
    throw Error(what + " '" + text + "': expected a positive diameter");
  }
  if (!in_voxels(q) && !is_physical_length_unit(q.unit)) {
    throw Error(what + " '" + text + "': unknown unit " + q.unit + " (m, cm, mm, um, vox)");
  }
}

double diameter_in_voxels(const std::string& text, const Stack& stack, const std::string& what) {
  check_diameter(text, what);
  const Quantity q = parse_quantity(text, what);
  if (in_voxels(q)) return q.value;
  if (!stack.voxel_size) {
    throw Error(what + " '" + text + "': " + stack.source +
                " has no voxel size: give the diameter in voxels, or --voxel-size");
  }
  return convert_length(q.value, q.unit, stack.unit) / stack.voxel_size->x();
}

}  // namespace granmem
