#include "granmem/calibration/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string_view>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;

// Tic labels such as "0.246" that fit side by side across a 420-pixel panel's plot.
constexpr double kLabelsAcrossAPanel = 7;

// A perceptual, colour-blind-safe map (matplotlib's viridis, 9 stops).
constexpr const char* kViridis =
    "set palette defined (0 '#440154', 1 '#472d7b', 2 '#3b528b', 3 '#2c728e', 4 '#21918c', "
    "5 '#28ae80', 6 '#5ec962', 7 '#addc30', 8 '#fde725')";

std::string quoted(const std::string& text) {
  std::string q = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

// A name given by the user (a run's label, a file's stem) as gnuplot's enhanced text shows
// it: its _ ^ @ & ~ { } as themselves, not as sub- and superscripts.
std::string plain(const std::string& text) {
  std::string p;
  for (char c : text) {
    if (std::string_view("_^@&~{}").find(c) != std::string_view::npos) p += '\\';
    p += c;
  }
  return p;
}

// Writes the data and the script (whose `plot` part is `body`, data in `<name>.dat`), runs
// gnuplot once for the PNG and once for the SVG, each into a temporary file renamed into
// place.
std::vector<fs::path> draw(const fs::path& dir, const std::string& name, const std::string& data,
                           const std::string& body, const std::string& size = "800,600") {
  fs::create_directories(dir);
  const fs::path dat = dir / (name + ".dat"), gp = dir / (name + ".gp");
  {
    AtomicFile f(dat);
    std::ofstream(f.temp_path()) << data;
    f.commit();
  }
  {
    AtomicFile f(gp);
    std::ofstream out(f.temp_path());
    out << "# " << name << ": drawn by granmem; `gnuplot " << name << ".gp` draws it again\n"
        << "if (!exists(\"term\")) term = \"pngcairo\"\n"
        << "if (term eq \"svg\") { set terminal svg size " << size
        << " font \"Sans,13\" background rgb \"white\"; set output \"" << name << ".svg\" }"
        << " else { set terminal pngcairo size " << size << " font \"Sans,12\"; set output \""
        << name << ".png\" }\n"
        << "set datafile missing \"nan\"\nset key top right\nset grid\n"
        << body;
    f.commit();
  }
  std::vector<fs::path> written{dat, gp};
  for (const std::string term : {"pngcairo", "svg"}) {
    const std::string ext = term == "svg" ? ".svg" : ".png";
    const fs::path target = dir / (name + ext);
    AtomicFile f(target);
    // gnuplot runs in `dir` so that the script's relative names hold; its output goes to a
    // temporary name that is then renamed into place.
    const std::string command = "cd " + quoted(dir.string()) + " && gnuplot -e " +
                                quoted("term='" + term + "'") + " " + quoted(gp.filename()) +
                                " 2> " + quoted(name + ".log") + " && mv " + quoted(name + ext) +
                                " " + quoted(f.temp_path().filename());
    if (std::system(command.c_str()) != 0) {
      std::ifstream log(dir / (name + ".log"));
      std::string first;
      std::getline(log, first);
      throw Error("gnuplot failed to draw " + target.string() +
                  (first.empty() ? " (is gnuplot installed? Debian: gnuplot-nox)" : ": " + first));
    }
    f.commit();
    written.push_back(target);
  }
  fs::remove(dir / (name + ".log"));
  return written;
}

// Log axes spanning about a decade get too few tics: the design's own values instead, but
// not one nearer another than a label's width, 1/`slots` of the axis `range` in log (and
// 20 %): a refined run's beside a design's would overlap; the values with more runs first,
// then the rounder (a design's 0.4 before a fit's 0.367).
std::string design_tics(const std::vector<double>& runs, std::array<double, 2> range,
                        double slots) {
  const double apart = std::max(1.2, std::pow(range[1] / range[0], 1 / slots));
  std::map<double, int> count;
  for (double x : runs)
    ++count[x];
  std::vector<std::pair<double, int>> by_runs(count.begin(), count.end());
  auto digits = [](double x) {
    std::ostringstream text;
    text << x;
    return text.str().size();
  };
  std::stable_sort(by_runs.begin(), by_runs.end(), [&](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : digits(a.first) < digits(b.first);
  });
  std::set<double> tics;
  for (const auto& run : by_runs) {
    const double x = run.first;  // a plain name: C++17 lambdas cannot capture a binding
    const bool crowded = std::any_of(tics.begin(), tics.end(),
                                     [&](double t) { return std::max(x / t, t / x) < apart; });
    if (!crowded) tics.insert(x);
  }
  std::ostringstream t;
  for (double x : tics)
    t << (x == *tics.begin() ? "(" : ", ") << "\"" << x << "\" " << x;
  return t.str() + ")";
}

}  // namespace

std::vector<fs::path> plot_log_pdfs(const fs::path& dir, const std::string& name,
                                    const std::vector<Sample>& samples, const std::string& x_label,
                                    const std::string& title, int bins) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const Sample& s : samples) {
    for (double v : s.values) {
      if (std::isfinite(v) && v > 0) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
  }
  if (!(hi > lo)) throw Error(name + ": no positive values to draw");
  DensityOptions o;
  o.bins = std::size_t(bins);
  o.scale = BinScale::logarithmic;
  o.range = std::make_pair(lo, hi);
  std::ostringstream data, plot;
  data.precision(8);
  // The pdfs peak mid-axis and fall off to the right: the lower left is where the key is free.
  plot << "set title " << quoted(title)
       << "\nset key bottom left\nset logscale xy\nset format xy \"10^{%T}\"\n"
       << "set xlabel " << quoted(x_label) << "\nset ylabel \"probability density\"\nplot ";
  const char* marks[] = {"7", "6", "5", "4", "9", "8"};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Table pdf = probability_density(samples[k].values, o);
    data << "# " << samples[k].label << "\n# bin_center density\n";
    for (std::size_t r = 0; r < pdf.rows(); ++r) {
      if (pdf["density"].values[r] > 0) {
        data << pdf["bin_center"].values[r] << " " << pdf["density"].values[r] << "\n";
      }
    }
    data << "\n\n";
    plot << (k ? ", " : "") << quoted(name + ".dat") << " index " << k
         << " using 1:2 with linespoints pt " << marks[k % 6] << " title "
         << quoted(plain(samples[k].label));
  }
  plot << "\n";
  return draw(dir, name, data.str(), plot.str());
}

std::vector<fs::path> plot_relaxation(const fs::path& dir, const std::string& name,
                                      const std::vector<Relaxation>& runs,
                                      const std::string& y_label, const std::string& title) {
  std::ostringstream data, plot, fits;
  data.precision(8);
  plot << "set title " << quoted(title)
       << "\nset logscale xy\nset format y \"10^{%T}\"\nset xlabel \"cycle\"\nset ylabel "
       << quoted(y_label) << "\n";
  const char* marks[] = {"7", "2", "5", "4"};
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const Relaxation& r = runs[k];
    data << "# " << r.label << "\n# cycle mean-steady\n";
    for (std::size_t i = 0; i < r.cycle.size(); ++i) {
      const double excess = r.mean[i] - r.fit.steady;
      if (std::isfinite(excess) && excess > 0) data << r.cycle[i] << " " << excess << "\n";
    }
    data << "\n\n";
    char label[160];
    std::snprintf(label, sizeof label, "%s: n^{-%.2f [%.2f, %.2f]}", plain(r.label).c_str(),
                  r.fit.exponent, r.fit.exponent_ci95[0], r.fit.exponent_ci95[1]);
    fits << ", " << r.fit.amplitude << " * x**(-" << r.fit.exponent << ") with lines dt 2 lc "
         << k + 1 << " lw 2 title " << quoted(label);
  }
  plot << "plot ";
  for (std::size_t k = 0; k < runs.size(); ++k) {
    plot << (k ? ", " : "") << quoted(name + ".dat") << " index " << k
         << " using 1:2 with points pt " << marks[k % 4] << " lc " << k + 1 << " title "
         << quoted(plain(runs[k].label));
  }
  plot << fits.str() << "\n";
  return draw(dir, name, data.str(), plot.str());
}

std::vector<fs::path> plot_fields(const fs::path& dir, const std::string& name,
                                  const std::vector<Field>& panels, const std::string& axis_label,
                                  const std::string& value_label) {
  // One colour scale for all panels: up to the 98th percentile, so that a few grains at the
  // wall do not wash the pattern out.
  std::vector<double> all;
  for (const Field& f : panels)
    all.insert(all.end(), f.value.begin(), f.value.end());
  const double top = quantile_in_place(all, 0.98);
  if (all.empty()) throw Error(name + ": no values to draw");
  std::ostringstream data, plot;
  data.precision(8);
  plot << "set multiplot layout 1," << panels.size() << "\nset size ratio -1\nunset key\n"
       << kViridis << "\nset cbrange [0:" << top << "]\nset cblabel " << quoted(value_label)
       << "\nset xlabel " << quoted("y " + axis_label) << "\nset ylabel "
       << quoted("z " + axis_label) << "\n";
  for (std::size_t k = 0; k < panels.size(); ++k) {
    const Field& f = panels[k];
    data << "# " << f.title << "\n# y z value\n";
    for (std::size_t i = 0; i < f.value.size(); ++i) {
      if (std::isfinite(f.value[i])) data << f.y[i] << " " << f.z[i] << " " << f.value[i] << "\n";
    }
    data << "\n\n";
    plot << "set title " << quoted(f.title) << "\nplot " << quoted(name + ".dat") << " index " << k
         << " using 1:2:3 with points pt 7 ps 0.8 palette\n";
  }
  plot << "unset multiplot\n";
  const std::string size = std::to_string(520 * panels.size()) + ",520";
  return draw(dir, name, data.str(), plot.str(), size);
}

std::vector<fs::path> plot_curves(const fs::path& dir, const std::string& name,
                                  const std::vector<Curve>& curves, const std::string& x_label,
                                  const std::string& y_label, const std::string& title,
                                  bool log_x) {
  std::ostringstream data, plot;
  data.precision(8);
  plot << "set title " << quoted(title) << "\nset xlabel " << quoted(x_label) << "\nset ylabel "
       << quoted(y_label) << "\nset key outside right\n"
       << (log_x ? "set logscale x\n" : "") << "plot ";
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const Curve& c = curves[k];
    data << "# " << c.label << "\n";
    for (std::size_t i = 0; i < c.x.size(); ++i)
      data << c.x[i] << " " << c.y[i] << " " << (c.error.empty() ? 0.0 : c.error[i]) << "\n";
    data << "\n\n";
    plot << (k ? ", " : "") << quoted(name + ".dat") << " index " << k
         << (c.error.empty()
                 ? (c.points ? " using 1:2 with linespoints pt 7" : " using 1:2 with lines lw 2")
                 : " using 1:2:3 with yerrorbars pt 7")
         << " lc " << k + 1 << " title " << quoted(c.label);
  }
  plot << "\n";
  return draw(dir, name, data.str(), plot.str(), "900,600");
}

std::vector<fs::path> plot_observable_fit(const fs::path& dir, const std::string& name,
                                          const std::vector<ObservablePanel>& panels, double mu_s,
                                          std::array<double, 2> ci95, double true_mu_s,
                                          const std::string& title, const ObservableFitKey& key) {
  if (panels.empty()) throw Error("observable fit figure: no observable");
  // The panels and, in the slot after them, the key alone: beside the last panel it would
  // run out of the figure wherever that is in the last column.
  const int slots = int(panels.size()) + 1;
  const int columns = slots <= 4 ? 2 : slots <= 6 || slots == 9 ? 3 : 4;
  const int rows = (slots + columns - 1) / columns;
  // The range: the design's frictions and the fit, with the interval where it is finite
  // (one that reaches 0 or infinity, an observable that cannot bound it, runs to the edge).
  double lowest = mu_s, highest = mu_s;
  for (const ObservablePanel& panel : panels) {
    for (double m : panel.run_mu_s) {
      lowest = std::min(lowest, m);
      highest = std::max(highest, m);
    }
  }
  if (ci95[0] > 0) lowest = std::min(lowest, ci95[0]);
  if (std::isfinite(ci95[1])) highest = std::max(highest, ci95[1]);
  lowest /= 1.25;
  highest *= 1.25;
  std::ostringstream data, plot;
  data.precision(8);
  plot << "set multiplot layout " << rows << "," << columns << " title " << quoted(title)
       << "\nset logscale x\nset xlabel \"mu_s\"\nset key off\nset grid\n"
       << "set xrange [" << lowest << ":" << highest << "]\nset xtics "
       << design_tics(panels.front().run_mu_s, {lowest, highest}, kLabelsAcrossAPanel) << "\n"
       << "set object 1 rect from " << (ci95[0] > lowest ? ci95[0] : lowest) << ", graph 0 to "
       << (ci95[1] < highest ? ci95[1] : highest)
       << ", graph 1 behind fc rgb \"#f4a582\" fs solid 0.35 noborder\n"
       << "set arrow 1 from " << mu_s << ", graph 0 to " << mu_s
       << ", graph 1 nohead lw 2 lc rgb \"#b2182b\"\n";
  if (std::isfinite(true_mu_s)) {
    plot << "set arrow 2 from " << true_mu_s << ", graph 0 to " << true_mu_s
         << ", graph 1 nohead lw 2 dt 2 lc rgb \"black\"\n";
  }
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const ObservablePanel& panel = panels[p];
    data << "# " << panel.label << ": runs (mu_s, value, packing)\n";
    for (std::size_t k = 0; k < panel.run_mu_s.size(); ++k)
      data << panel.run_mu_s[k] << " " << panel.run_value[k] << " " << panel.run_packing[k] + 1
           << "\n";
    data << "\n\n# " << panel.label << ": trend (mu_s, value)\n";
    for (std::size_t k = 0; k < panel.curve_mu_s.size(); ++k)
      data << panel.curve_mu_s[k] << " " << panel.curve[k] << "\n";
    data << "\n\n";
    plot << "set ylabel " << quoted(panel.label) << "\nset object 2 rect from graph 0, first "
         << panel.experiment - panel.experiment_error << " to graph 1, first "
         << panel.experiment + panel.experiment_error
         << " behind fc rgb \"#92c5de\" fs solid 0.45 noborder\n"
         << "set arrow 3 from graph 0, first " << panel.experiment << " to graph 1, first "
         << panel.experiment << " nohead lw 1.5 lc rgb \"#2166ac\"\n";
    plot << "plot " << quoted(name + ".dat") << " index " << 2 * p
         << " using 1:2:3 with points pt 7 ps 1.2 lc variable, " << quoted(name + ".dat")
         << " index " << 2 * p + 1 << " using 1:2 with lines lw 2 lc rgb \"#404040\"\n";
  }
  plot << "unset object 1\nunset object 2\nunset arrow 1\nunset arrow 2\nunset arrow 3\n"
       << "unset border\nunset tics\nunset grid\nunset xlabel\nunset ylabel\nunset logscale\n"
       << "set xrange [0:1]\nset yrange [0:1]\nset key center center vertical Left reverse\n"
       << "plot NaN with points pt 7 ps 1.2 lc 1 title " << quoted(key.runs) << ", "
       << "NaN with lines lw 2 lc rgb \"#404040\" title \"trend\", "
       << "NaN with lines lw 8 lc rgb \"#92c5de\" title " << quoted(key.experiment) << ", "
       << "NaN with lines lw 8 lc rgb \"#f4a582\" title \"fitted mu_s, 95 %\", "
       << "NaN with lines lw 2 lc rgb \"#b2182b\" title \"fitted mu_s\""
       << (std::isfinite(true_mu_s)
               ? ", NaN with lines lw 2 dt 2 lc rgb \"black\" title \"true mu_s\""
               : "")
       << "\nunset multiplot\n";
  const std::string size = std::to_string(420 * columns) + "," + std::to_string(330 * rows + 60);
  return draw(dir, name, data.str(), plot.str(), size);
}

std::vector<fs::path> plot_fits_apart(const fs::path& dir, const std::string& name,
                                      const std::vector<double>& x, const std::vector<double>& mu_s,
                                      const std::vector<double>& error, double fit,
                                      std::array<double, 2> ci95, double true_mu_s,
                                      const std::string& x_label, const std::string& title) {
  if (x.empty()) throw Error("fits apart figure: no fit");
  std::ostringstream data, plot;
  data.precision(8);
  data << "# " << x_label << ", mu_s, its error\n";
  for (std::size_t k = 0; k < x.size(); ++k)
    data << x[k] << " " << mu_s[k] << " " << error[k] << "\n";
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  const double pad = std::max(0.5, (*hi - *lo) * 0.05);
  plot << "set title " << quoted(title) << "\nset xlabel " << quoted(x_label)
       << "\nset ylabel \"mu_s\"\nset grid\nset key outside bottom center horizontal\n"
       << "set xrange [" << *lo - pad << ":" << *hi + pad << "]\n"
       << "set object 1 rect from graph 0, first " << ci95[0] << " to graph 1, first " << ci95[1]
       << " behind fc rgb \"#f4a582\" fs solid 0.35 noborder\n"
       << "plot " << quoted(name + ".dat")
       << " using 1:2:3 with yerrorbars pt 7 ps 1.2 lc rgb \"#5e3c99\" title \"each fit\", " << fit
       << " with lines lw 2 lc rgb \"#b2182b\" title \"their mean, 95 % shaded\"";
  if (std::isfinite(true_mu_s))
    plot << ", " << true_mu_s << " with lines lw 2 dt 2 lc rgb \"black\" title \"true mu_s\"";
  plot << "\n";
  return draw(dir, name, data.str(), plot.str(), "800,500");
}

std::vector<fs::path> plot_joint_region(const fs::path& dir, const std::string& name,
                                        const std::vector<double>& run_x,
                                        const std::vector<double>& run_y,
                                        const std::vector<std::array<double, 2>>& region,
                                        std::array<double, 2> fit, std::array<double, 2> truth,
                                        const std::string& title) {
  std::ostringstream data, plot;
  data.precision(8);
  data << "# twin runs: mu_s mu_r\n";
  for (std::size_t k = 0; k < run_x.size(); ++k)
    data << run_x[k] << " " << run_y[k] << "\n";
  data << "\n\n# joint 95 % region: mu_s mu_r\n";
  for (const auto& p : region)
    data << p[0] << " " << p[1] << "\n";
  data << "\n\n# fit\n" << fit[0] << " " << fit[1] << "\n\n\n# truth\n";
  if (std::isfinite(truth[0]) && std::isfinite(truth[1])) data << truth[0] << " " << truth[1];
  data << "\n";
  std::array<double, 2> lo{fit[0], fit[1]}, hi = lo;
  auto extend = [&](double x, double y) {
    lo = {std::min(lo[0], x), std::min(lo[1], y)};
    hi = {std::max(hi[0], x), std::max(hi[1], y)};
  };
  for (std::size_t k = 0; k < run_x.size(); ++k)
    extend(run_x[k], run_y[k]);
  for (const auto& p : region)
    extend(p[0], p[1]);
  const std::string file = quoted(name + ".dat");
  const std::array<double, 2> x_range{lo[0] / 1.4, hi[0] * 1.4}, y_range{lo[1] / 1.4, hi[1] * 1.4};
  plot << "set xtics " << design_tics(run_x, x_range, 2 * kLabelsAcrossAPanel) << "\nset ytics "
       << design_tics(run_y, y_range, 2 * kLabelsAcrossAPanel) << "\nset title " << quoted(title)
       << "\nset logscale xy\nset xlabel \"sliding friction mu_s\""
       << "\nset ylabel \"rolling friction mu_r\"\nset key outside bottom center horizontal\n"
       << "set xrange [" << x_range[0] << ":" << x_range[1] << "]\nset yrange [" << y_range[0]
       << ":" << y_range[1] << "]\n"
       << "plot " << file
       << " index 1 using 1:2 with filledcurves closed fc rgb \"#f4a582\" fs solid 0.45 "
          "title \"joint 95 % region\", "
       << file
       << " index 0 using 1:2 with points pt 6 ps 1.5 lc rgb \"#404040\" title \"twin runs\", "
       << file << " index 2 using 1:2 with points pt 7 ps 1.8 lc rgb \"#b2182b\" title \"fit\"";
  if (std::isfinite(truth[0]) && std::isfinite(truth[1])) {
    plot << ", " << file << " index 3 using 1:2 with points pt 3 ps 2.2 lw 2 lc rgb \"black\" "
         << "title \"true\"";
  }
  plot << "\n";
  return draw(dir, name, data.str(), plot.str(), "800,650");
}

}  // namespace granmem
