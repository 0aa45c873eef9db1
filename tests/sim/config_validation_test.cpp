// Unphysical settings are refused with a granmem::Error naming the parameter (and, for the
// time step, saying why), before anything runs.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "checks.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/simulation.hpp"
#include "sim_checks.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

using testing::error_message;
using testing::kDensity;
using testing::kRadius;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Grains two_grains(double radius = kRadius) {
  Grains g;
  g.add(0, {0.005, 0.015, 0.003}, radius, kDensity);
  g.add(1, {0.015, 0.015, 0.003}, radius, kDensity);
  return g;
}

// The message of the Error a simulation with physics `p` is refused with ("" if accepted).
std::string refusal(const PhysicsOptions& p, const Grains& g = two_grains()) {
  try {
    Simulation sim(g, testing::wide_box(0.05), p);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

struct Bad {
  std::string parameter;  // the name the message must contain
  std::function<void(PhysicsOptions&)> set;
};

TEST(ConfigValidation, UnphysicalContactAndPhysicsParametersAreRefusedByName) {
  const std::vector<Bad> cases = {
      {"k_n", [](PhysicsOptions& p) { p.contact.k_n = 0; }},
      {"k_n", [](PhysicsOptions& p) { p.contact.k_n = -4000; }},
      {"k_n", [](PhysicsOptions& p) { p.contact.k_n = kNaN; }},
      {"k_t/k_n", [](PhysicsOptions& p) { p.contact.k_t_over_k_n = -0.1; }},
      {"restitution_n", [](PhysicsOptions& p) { p.contact.restitution_n = 0; }},
      {"restitution_n", [](PhysicsOptions& p) { p.contact.restitution_n = -0.2; }},
      {"restitution_n", [](PhysicsOptions& p) { p.contact.restitution_n = 1.01; }},
      {"restitution_n", [](PhysicsOptions& p) { p.contact.restitution_n = kNaN; }},
      {"restitution_t", [](PhysicsOptions& p) { p.contact.restitution_t = 0; }},
      {"restitution_t", [](PhysicsOptions& p) { p.contact.restitution_t = 2; }},
      {"mu_s", [](PhysicsOptions& p) { p.contact.mu_s = -0.2; }},
      {"mu_s", [](PhysicsOptions& p) { p.contact.mu_s = kNaN; }},
      {"mu_r", [](PhysicsOptions& p) { p.contact.mu_r = -0.01; }},
      {"mu_t", [](PhysicsOptions& p) { p.contact.mu_t = -0.001; }},
      {"beta", [](PhysicsOptions& p) { p.contact.beta = -0.5; }},
      {"beta", [](PhysicsOptions& p) { p.contact.beta = 1.5; }},
      {"wall friction", [](PhysicsOptions& p) { p.wall.mu_s = -0.2; }},
      {"wall friction", [](PhysicsOptions& p) { p.wall.mu_r = -0.01; }},
      {"wall friction", [](PhysicsOptions& p) { p.wall.mu_t = kNaN; }},
      {"density", [](PhysicsOptions& p) { p.density = 0; }},
      {"gravity", [](PhysicsOptions& p) { p.gravity = -9.81; }},
      {"time step", [](PhysicsOptions& p) { p.dt = 0; }},
      {"time step", [](PhysicsOptions& p) { p.dt = -25e-6; }},
      {"skin", [](PhysicsOptions& p) { p.skin = 0; }},
      {"damping", [](PhysicsOptions& p) { p.background_damping = -1; }},
  };
  for (const Bad& c : cases) {
    PhysicsOptions p;
    c.set(p);
    const std::string message = refusal(p);
    EXPECT_NE(message.find(c.parameter), std::string::npos)
        << "expected a refusal naming " << c.parameter << ", got '" << message << "'";
    EXPECT_EQ(message.rfind("simulation: ", 0), 0u) << message;
  }
}

TEST(ConfigValidation, TheLimitsThemselvesAreAccepted) {
  PhysicsOptions p;
  EXPECT_EQ(refusal(p), "") << "the paper's defaults";
  p.contact.restitution_n = 1;
  p.contact.restitution_t = 1;
  p.contact.mu_s = p.contact.mu_r = p.contact.mu_t = 0;
  p.contact.beta = 0;
  p.wall = {0, 0, 0};
  p.gravity = 0;
  EXPECT_EQ(refusal(p), "");
  p.contact.beta = 1;
  EXPECT_EQ(refusal(p), "");
}

TEST(ConfigValidation, TimeStepTooLongForTheCollisionIsRefusedWithTheReason) {
  PhysicsOptions p;
  const double m = 4.0 / 3.0 * M_PI * std::pow(kRadius, 3) * kDensity;
  const double duration = contact_duration(p.contact.k_n, p.contact.restitution_n, m / 2);
  // pi / w_d with w_d = w_0 sqrt(1 - zeta^2), zeta = |ln e| / sqrt(pi^2 + ln^2 e): 0.347 ms
  // for e = 0.2 (0.309 ms undamped), which the paper's 25 us resolves in ~14 steps.
  const double zeta = std::abs(std::log(0.2)) / std::sqrt(M_PI * M_PI + std::pow(std::log(0.2), 2));
  EXPECT_NEAR(duration, M_PI / (std::sqrt(p.contact.k_n / (m / 2)) * std::sqrt(1 - zeta * zeta)),
              1e-15);
  EXPECT_NEAR(duration, 0.347e-3, 0.001e-3);
  p.dt = duration / 10 * 0.999;
  EXPECT_EQ(refusal(p), "");
  p.dt = duration / 10 * 1.001;
  const std::string message = refusal(p);
  for (const char* part : {"time step", "collision", "steps", "at least 10", "dt <="}) {
    EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
  }
  // The smallest grain sets the limit.
  Grains g = two_grains();
  g.add(2, {0.03, 0.03, 0.03}, 0.5 * kRadius, kDensity);
  p.dt = 25e-6;
  EXPECT_NE(refusal(p, g).find("time step"), std::string::npos);
  // A stiffer spring shortens the collision.
  p = PhysicsOptions{};
  p.contact.k_n = 4 * 4000;
  EXPECT_NE(refusal(p).find("time step"), std::string::npos);
}

TEST(ConfigValidation, GrainWithoutRadiusIsRefused) {
  EXPECT_NE(refusal(PhysicsOptions{}, two_grains(0)).find("radius"), std::string::npos);
}

TEST(ConfigValidation, DepositRefusesImpossibleOptions) {
  const PhysicsOptions p;
  auto refused = [&](const std::function<void(DepositOptions&)>& set) {
    DepositOptions o;
    o.grains = 10;
    set(o);
    return error_message([&] { deposit(o, p); });
  };
  EXPECT_NE(refused([](DepositOptions& o) { o.grains = 0; }).find("grain"), std::string::npos);
  EXPECT_NE(refused([](DepositOptions& o) { o.radius = 0; }).find("radius"), std::string::npos);
  EXPECT_NE(refused([](DepositOptions& o) { o.polydispersity = 1; }).find("polydispersity"),
            std::string::npos);
  EXPECT_NE(refused([](DepositOptions& o) { o.box_side = 0.009; }).find("box"), std::string::npos);
  EXPECT_NE(refused([](DepositOptions& o) { o.lid_mass = -1; }).find("lid mass"),
            std::string::npos);
  PhysicsOptions bad = p;
  bad.contact.k_n = -1;
  DepositOptions o;
  EXPECT_NE(error_message([&] { deposit(o, bad); }).find("k_n"), std::string::npos);
}

class CyclicValidation : public testing::TempDirTest {
 protected:
  // A loose pair of grains in a 2 cm box: enough for run_cycles to check its options.
  Simulation sim() {
    Container c;
    c.size = {0.02, 0.02};
    return Simulation(two_grains(), c, PhysicsOptions{});
  }
  CyclicOptions options() {
    CyclicOptions o;
    o.drive.amplitude = 1e-3;
    o.drive.period = 0.01;
    o.cycles = 1;
    o.out = path("run.h5");
    return o;
  }
  std::string refused(const std::function<void(CyclicOptions&)>& set) {
    CyclicOptions o = options();
    set(o);
    Simulation s = sim();
    ProtocolState state;
    const std::string message = error_message([&] { run_cycles(s, o, state); });
    EXPECT_EQ(s.step_count(), 0) << "ran before refusing";
    EXPECT_FALSE(std::filesystem::exists(o.out)) << "wrote before refusing";
    return message;
  }
};

TEST_F(CyclicValidation, ImpossibleDrivesAndCycleCountsAreRefusedByName) {
  EXPECT_NE(refused([](CyclicOptions& o) { o.cycles = 0; }).find("cycles"), std::string::npos);
  EXPECT_NE(refused([](CyclicOptions& o) { o.cycles = -2; }).find("cycles"), std::string::npos);
  EXPECT_NE(refused([](CyclicOptions& o) { o.drive.amplitude = -1e-3; }).find("amplitude"),
            std::string::npos);
  // Half the 2 cm box, or more.
  const std::string half = refused([](CyclicOptions& o) { o.drive.amplitude = 0.01; });
  EXPECT_NE(half.find("amplitude"), std::string::npos) << half;
  EXPECT_NE(half.find("half the box"), std::string::npos) << half;
  EXPECT_NE(refused([](CyclicOptions& o) { o.drive.amplitude = 0.015; }).find("amplitude"),
            std::string::npos);
  EXPECT_NE(refused([](CyclicOptions& o) { o.drive.period = 50e-6; }).find("period"),
            std::string::npos);
  EXPECT_NE(refused([](CyclicOptions& o) {
              o.tracked_grains = {0, 99};
            }).find("99"),
            std::string::npos);
}

TEST_F(CyclicValidation, AGoodDriveRuns) {
  CyclicOptions o = options();
  o.drive.amplitude = 0.0099;  // just under half the box
  Simulation s = sim();
  ProtocolState state;
  EXPECT_EQ(run_cycles(s, o, state).cycles_done, 1);
  EXPECT_EQ(s.step_count(), 400);
  EXPECT_EQ(s.container().y_wall, 0);  // back at rest at the end of the cycle
}

}  // namespace
}  // namespace granmem
