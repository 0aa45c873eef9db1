#include "granmem/sim/lammps_engine.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/lammps_dump.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/lammps_data.hpp"

namespace granmem {
namespace {

constexpr double kCm = 0.01;  // m per cm
constexpr const char* kFrames = "cycles.dump";
constexpr const char* kObserved = "cycles.txt";
constexpr const char* kOutput = "lammps.out";

void write_text(const std::filesystem::path& path, const std::string& text) {
  AtomicFile file(path);
  std::ofstream out(file.temp_path(), std::ios::binary);
  out << text;
  out.close();
  if (!out) throw Error(path.string() + ": cannot write");
  file.commit();
}

// The driven wall's position (cm) as a LAMMPS formula of the step: WallDrive::at at step
// k of the cycle's n, as run_cycles moves it.
std::string drive_formula(const WallDrive& d, std::int64_t steps_per_cycle) {
  std::ostringstream f;
  f.precision(17);
  const double a = d.amplitude / kCm;
  const std::string phase =
      "((step%" + std::to_string(steps_per_cycle) + ")/" + std::to_string(steps_per_cycle) + ")";
  if (d.shape == DriveShape::cosine) {
    if (d.symmetry == DriveSymmetry::asymmetric)
      f << 0.5 * a << "*(1-cos(2*PI*" << phase << "))";
    else
      f << 0.5 * a << "*sin(2*PI*" << phase << ")";
  } else if (d.symmetry == DriveSymmetry::asymmetric) {
    f << a << "*(1-abs(1-2*" << phase << "))";  // 0 -> A -> 0 at constant speed
  } else {
    f << 0.5 * a << "*(4*abs(((" << phase << "+0.75)%1)-0.5)-1)";  // 0, A/2, -A/2, 0
  }
  return f.str();
}

struct RunPlan {
  std::int64_t steps_per_cycle = 0, full_step = 0;
  std::int64_t first = 0;  // cycles done before this launch
  std::filesystem::path restart;
};

std::string run_input(const Simulation& sim, const CyclicOptions& o, const RunPlan& plan) {
  const PhysicsOptions& p = sim.physics();
  const ContactParameters& c = p.contact;
  std::ostringstream s;
  s.precision(17);
  s << "# written by granmem simulate --engine lammps; CGS units\n"
    << "variable data string packing.data\n"
    << "variable fresh index " << (plan.restart.empty() ? 1 : 0) << "\n"
    << "variable restart string " << (plan.restart.empty() ? "none" : plan.restart.string()) << "\n"
    << "variable lib string .\n"
    << "variable atomstyle string \"hybrid sphere dipole\"\n"
    << "variable kn index " << c.k_n * 1e3 << "\n"  // N/m -> dyne/cm
    << "variable en index " << c.restitution_n << "\n"
    << "variable et index " << c.restitution_t << "\n"
    << "variable ktkn index " << c.k_t_over_k_n << "\n"
    << "variable mus index " << c.mu_s << "\nvariable mur index " << c.mu_r
    << "\nvariable mut index " << c.mu_t << "\n"
    << "variable wmus index " << p.wall.mu_s << "\nvariable wmur index " << p.wall.mu_r
    << "\nvariable wmut index " << p.wall.mu_t << "\n"
    << "variable beta index " << c.beta << "\n"
    << "variable R index " << sim.grains().radius.front() / kCm << "\n"
    << "variable rho index " << p.density * 1e-3 << "\n"
    << "variable tstep index " << p.dt << "\n"
    << "variable g index " << p.gravity / kCm << "\n"
    << "variable skin index " << p.skin / kCm << "\n"
    << "variable nper index " << plan.steps_per_cycle << "\n"
    << "variable nfull index " << plan.full_step << "\n"
    << "variable first index " << plan.first << "\n"
    << "variable cycles index " << o.cycles << "\n"
    << "variable every index " << (o.checkpoint_every > 0 ? o.checkpoint_every : o.cycles) << "\n"
    << "variable ydrive equal \"" << drive_formula(o.drive, plan.steps_per_cycle) << "\"\n"
    << "variable frames string " << kFrames << "\n"
    << "variable observed string " << kObserved << "\n"
    << "include cycles.lmp\n";
  return s.str();
}

// [mpirun -np N] lmp -in in.run.lmp ..., run in the run's folder.
std::vector<std::string> command_line(const LammpsEngineOptions& e) {
  std::vector<std::string> argv;
  if (e.ranks > 1) {
    argv = {e.mpirun, "-np", std::to_string(e.ranks)};
    if (geteuid() == 0) argv.push_back("--allow-run-as-root");  // OpenMPI refuses root else
  }
  for (const char* a : {"-in", "in.run.lmp", "-log", "log.lammps", "-echo", "none"})
    argv.push_back(a);
  argv.insert(argv.end() - 6, e.lmp);
  return argv;
}

// Starts LAMMPS in `folder`, its output into lammps.out, in a process group of its own (a
// Ctrl-C reaches granmem, which ends it) that ends with granmem.
pid_t launch(const LammpsEngineOptions& e) {
  const std::vector<std::string> args = command_line(e);
  std::vector<char*> argv;
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const std::string folder = e.folder.string(), out = (e.folder / kOutput).string();
  const pid_t pid = fork();
  if (pid < 0) throw Error("--engine lammps: cannot start a process");
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    const int fd = open(out.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (chdir(folder.c_str()) != 0 || fd < 0) _exit(126);
    dup2(fd, 1);
    dup2(fd, 2);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  setpgid(pid, pid);  // as the child does: whichever runs first, the group exists for kill
  return pid;
}

// LAMMPS's first ERROR line in its output, or its last line.
std::string lammps_error(const std::filesystem::path& out) {
  std::ifstream in(out);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.rfind("ERROR", 0) == 0) return line;
    if (!line.empty()) last = line;
  }
  return last;
}

// The per-cycle lines: cycle -> (full-compression force, end force, lid height, kinetic
// energy, contacts per grain), CGS; a cycle written twice (a run resumed from an earlier
// restart) keeps its newer line. While LAMMPS runs (`partial`) a line it is writing ends
// the reading; after it, a line that is not one is an Error.
std::map<std::int64_t, std::array<double, 5>> read_observed(const std::filesystem::path& path,
                                                            bool partial = false) {
  std::map<std::int64_t, std::array<double, 5>> rows;
  std::ifstream in(path);
  std::string word, line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::int64_t cycle = 0;
    std::array<std::string, 5> text;
    std::array<double, 5> value{};
    bool ok = bool(s >> word >> cycle >> text[0] >> text[1] >> text[2] >> text[3] >> text[4]) &&
              word == "cycle";
    for (std::size_t k = 0; ok && k < text.size(); ++k) {
      char* end = nullptr;
      value[k] = std::strtod(text[k].c_str(), &end);  // nan and inf as C reads them
      ok = end == text[k].c_str() + text[k].size();
    }
    if (!ok && partial) break;
    if (!ok) throw Error(path.string() + ": not a line of LAMMPS's cycles: '" + line + "'");
    rows[cycle] = value;
  }
  return rows;
}

// Ends LAMMPS (and mpirun's ranks): SIGTERM to its group, SIGKILL if it has not ended
// within 10 s.
void end_process_group(pid_t pid) {
  if (kill(-pid, SIGTERM) != 0) kill(pid, SIGTERM);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) != pid) {
    if (std::chrono::steady_clock::now() > give_up) {
      kill(-pid, SIGKILL);
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// Polls LAMMPS until it ends (its exit status) or `stop` is set (-1 after ending it),
// reporting the cycles done as its per-cycle lines appear.
int wait_for(pid_t pid, const std::filesystem::path& observed, std::int64_t first,
             std::int64_t cycles, std::size_t grains, std::int64_t steps_per_cycle,
             const std::function<void(const CyclicProgress&)>& progress,
             const std::atomic<bool>* stop) {
  const auto start = std::chrono::steady_clock::now();
  auto last_report = start;
  std::int64_t reported = first;
  while (true) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    if (stop && stop->load()) {
      end_process_group(pid);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto now = std::chrono::steady_clock::now();
    if (!progress || now - last_report < std::chrono::seconds(2)) continue;
    last_report = now;
    const auto rows = read_observed(observed, true);
    const std::int64_t done = rows.empty() ? first : std::max(first, rows.rbegin()->first);
    if (done == reported) continue;
    reported = done;
    const double seconds = std::chrono::duration<double>(now - start).count();
    CyclicProgress p;
    p.cycle = done;
    p.cycles = cycles;
    p.particle_steps_per_second =
        double(done - first) * double(steps_per_cycle) * double(grains) / seconds;
    p.seconds_left = seconds * double(cycles - done) / double(done - first);
    progress(p);
  }
}

// The dump's end-of-cycle frames and the per-cycle lines as granmem's store.
void write_store(const Simulation& sim, const CyclicOptions& o, const RunPlan& plan,
                 const std::filesystem::path& folder) {
  std::vector<std::size_t> all(sim.grains().size());
  for (std::size_t i = 0; i < all.size(); ++i)
    all[i] = i;
  RunHeader h = cyclic_run_header(sim, all, kSampleEndOfCycle, o.parameters);
  h.has_orientation = false;  // LAMMPS carries the cavity axis only
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < h.id.size(); ++i)
    index[h.id[i]] = i;
  const LammpsDump dump = read_lammps_dump(folder / kFrames, {1});
  const Table& t = dump.table;
  std::map<std::int64_t, Frame> frames;  // by cycle; a frame dumped twice keeps the newer
  for (std::size_t row = 0; row < t.rows(); ++row) {
    const auto step = std::int64_t(t["frame"].values[row]);
    if (step % plan.steps_per_cycle != 0) continue;
    const std::int64_t cycle = step / plan.steps_per_cycle;
    auto [it, fresh] = frames.try_emplace(cycle, Frame::unknown(h));
    Frame& f = it->second;
    f.step = cycle;
    f.time = double(step) * sim.physics().dt;
    const auto grain = index.find(std::int64_t(t["particle"].values[row]));
    if (grain == index.end()) throw Error(folder.string() + ": LAMMPS dumped an unknown grain");
    const auto r = Eigen::Index(grain->second);
    f.position.row(r) << t["x"].values[row] * kCm, t["y"].values[row] * kCm,
        t["z"].values[row] * kCm;
    f.axis.row(r) = Eigen::Vector3d(t["ax"].values[row], t["ay"].values[row], t["az"].values[row])
                        .normalized()
                        .transpose();
  }
  const auto observed = read_observed(folder / kObserved);
  double volume = 0;
  for (double radius : sim.grains().radius)
    volume += 4.0 / 3.0 * M_PI * radius * radius * radius;
  const double base = sim.container().size.x() * sim.container().size.y();
  std::map<std::string, Observable> obs;
  auto record = [&](const char* name, const char* unit, std::int64_t cycle, double value) {
    Observable& x = obs[name];
    x.unit = unit;
    x.value.push_back(value);
    x.step.push_back(cycle);
    x.time.push_back(double(cycle * plan.steps_per_cycle) * sim.physics().dt);
  };
  TrajectoryWriter writer(o.out, h);
  for (std::int64_t cycle = 0; cycle <= o.cycles; ++cycle) {
    const auto f = frames.find(cycle);
    const auto v = observed.find(cycle);
    if (f == frames.end() || v == observed.end()) {
      throw Error(folder.string() + ": LAMMPS wrote no frame or line for cycle " +
                  std::to_string(cycle));
    }
    writer.append(f->second);
    const auto& x = v->second;
    record("wall_force", "N", cycle, x[1] * 1e-5);  // dyne -> N
    record("wall_force_full_compression", "N", cycle, x[0] * 1e-5);
    record("lid_height", "m", cycle, x[2] * kCm);
    record("packing_fraction", "1", cycle, volume / (base * x[2] * kCm));
    record("kinetic_energy", "J", cycle, x[3] * 1e-7);  // erg -> J
    record("contacts_per_grain", "1", cycle, x[4]);
  }
  for (auto& [name, x] : obs)
    writer.set_observable(name, std::move(x));
  writer.commit();
}

// A program that execvp would start: a path to an executable file, or a name found so on
// $PATH.
bool can_run(const std::string& program) {
  if (program.empty()) return false;
  if (program.find('/') != std::string::npos) return access(program.c_str(), X_OK) == 0;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

}  // namespace

void check_lammps_protocol(const CyclicOptions& o, bool one_grain_size, bool lid) {
  if (!one_grain_size) {
    throw Error(
        "--engine lammps: the contact law maps onto LAMMPS for grains of one size only "
        "(bench/lammps/README.md); give --polydispersity 0");
  }
  if (!lid)
    throw Error("--engine lammps: the protocol on LAMMPS needs the lid (--lid-pressure > 0)");
  if (o.full_compression_frames || o.samples_per_cycle > 0 || !o.keep_states.empty()) {
    throw Error(
        "--engine lammps writes end-of-cycle frames only: --full-compression, "
        "--samples-per-cycle and --keep-states need --engine granmem");
  }
  if (o.first_cycle != 0)
    throw Error("--engine lammps numbers its cycles from 0: a run placed later needs granmem");
}

std::filesystem::path lammps_folder(const std::filesystem::path& out) {
  return out.parent_path() / (out.stem().string() + ".lammps");
}

void LammpsEngineOptions::validate() const {
  if (folder.empty()) throw Error("--engine lammps: no folder for LAMMPS's files");
  if (ranks < 1) throw Error("--ranks " + std::to_string(ranks) + ": expected 1 or more");
  if (!can_run(lmp)) {
    throw Error("--lammps '" + lmp +
                "': no such program (LAMMPS with the GRANULAR and DIPOLE packages; Debian: "
                "apt-get install lammps)");
  }
  if (ranks > 1 && !can_run(mpirun)) {
    throw Error("--ranks " + std::to_string(ranks) + ": no '" + mpirun +
                "' to start the ranks (Debian: apt-get install openmpi-bin)");
  }
}

std::pair<std::filesystem::path, std::int64_t> newest_lammps_restart(
    const std::filesystem::path& folder) {
  std::pair<std::filesystem::path, std::int64_t> newest{"", 0};
  if (!std::filesystem::is_directory(folder)) return newest;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("cycle", 0) != 0 || entry.path().extension() != ".restart") continue;
    const std::string digits = name.substr(5, name.size() - 5 - 8);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::int64_t cycle = std::stoll(digits);
    if (newest.first.empty() || cycle > newest.second) newest = {entry.path(), cycle};
  }
  return newest;
}

CyclicSummary run_cycles_on_lammps(const Simulation& sim, const CyclicOptions& o,
                                   const LammpsEngineOptions& e,
                                   const std::function<void(const CyclicProgress&)>& progress,
                                   const std::atomic<bool>* stop) {
  e.validate();
  const auto& radii = sim.grains().radius;
  check_lammps_protocol(
      o,
      std::all_of(radii.begin(), radii.end(),
                  [&](double r) { return std::abs(r - radii.front()) <= 1e-9 * r; }),
      sim.container().lid.present);
  RunPlan plan;
  plan.steps_per_cycle = std::llround(o.drive.period / sim.physics().dt);
  plan.full_step =
      std::llround(o.drive.full_compression_time() / o.drive.period * double(plan.steps_per_cycle));
  std::filesystem::create_directories(e.folder);
  const auto [restart, cycle] = newest_lammps_restart(e.folder);
  if (e.resume && !restart.empty()) {
    plan.restart = restart.filename();
    plan.first = cycle;
  } else {
    for (const char* stale : {kFrames, kObserved, kOutput})
      std::filesystem::remove(e.folder / stale);
    for (auto old = newest_lammps_restart(e.folder); !old.first.empty();
         old = newest_lammps_restart(e.folder))
      std::filesystem::remove(old.first);
    LammpsDataOptions data;
    data.density = sim.physics().density;
    data.cavity_axis_as_dipole = true;
    data.comment = "the packing of " + o.out.string();
    write_lammps_data(e.folder / "packing.data", sim.grains(), sim.container(), data);
  }
  for (const auto& [name, text] : lammps_scripts())
    write_text(e.folder / name, text);
  write_text(e.folder / "in.run.lmp", run_input(sim, o, plan));

  const auto start = std::chrono::steady_clock::now();
  CyclicSummary summary;
  if (stop && stop->load()) {  // stopped while the packing was made
    summary.interrupted = true;
    summary.cycles_done = plan.first;
    return summary;
  }
  if (plan.first < o.cycles) {
    const int status = wait_for(launch(e), e.folder / kObserved, plan.first, o.cycles,
                                sim.grains().size(), plan.steps_per_cycle, progress, stop);
    if (status == -1) {
      summary.interrupted = true;
      summary.cycles_done = newest_lammps_restart(e.folder).second;
      return summary;
    }
    if (status != 0) {
      throw Error("LAMMPS (" + (e.folder / kOutput).string() + ") failed with exit status " +
                  std::to_string(status) + ": " + lammps_error(e.folder / kOutput));
    }
  }
  write_store(sim, o, plan, e.folder);
  summary.cycles_done = o.cycles;
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.particle_steps_per_second =
      summary.wall_seconds > 0 ? double(o.cycles - plan.first) * double(plan.steps_per_cycle) *
                                     double(sim.grains().size()) / summary.wall_seconds
                               : 0;
  summary.written.push_back(o.out);
  return summary;
}

}  // namespace granmem
