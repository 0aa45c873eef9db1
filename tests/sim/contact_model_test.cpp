// One evaluation of the contact law between two unequal grains, against its formulas:
//   F_n = k_n delta - C_n v_n, C = 2 sqrt(m_red k) |ln e| / sqrt(pi^2 + ln^2 e);
//   sliding: F_t = -k_t xi - C_t v_t below the cap, mu_s |F_n| against v_t at it;
//     torques -l_i n x F_t on i and -l_j n x F_t on j;
//   rolling: at its cap the moment on i is l_ij n x F_r with |F_r| = mu_r beta |F_n| against
//     v_r = l_i (w_i x n) - l_j (w_j x n), and the opposite on j;
//   twisting: at its cap the moment on i is -mu_t mu_s beta l_ij |F_n| sign(v_tw) n with
//     v_tw = l_ij (w_i - w_j) . n, and the opposite on j.
// Each mode is isolated by choosing the spins: l_i w_i + l_j w_j = 0 moves no contact point
// (pure rolling), w parallel to n rolls nothing (pure twisting).
#include <gtest/gtest.h>

#include <cmath>

#include "granmem/sim/contact_model.hpp"
#include "sim_checks.hpp"

namespace granmem {
namespace {

using testing::kDensity;

constexpr double kRi = 0.0025, kRj = 0.002, kDt = 25e-6;

double mass(double r) {
  return 4.0 / 3.0 * M_PI * r * r * r * kDensity;
}

ContactParameters parameters() {
  ContactParameters p;
  p.mu_s = 0.3;
  p.mu_r = 0.1;
  p.mu_t = 0.2;
  return p;
}

const Eigen::Vector3d kZero = Eigen::Vector3d::Zero();
const Eigen::Vector3d kN = Eigen::Vector3d(1, 2, -2) / 3.0;  // from j to i
const Eigen::Vector3d kXi(0.01, 0.02, 0.03);
const Eigen::Vector3d kXj = kXi - (kRi + kRj - 1e-4) * kN;  // 0.1 mm overlap

// A tangent unit vector and its partner.
const Eigen::Vector3d kT1 = Eigen::Vector3d(2, 1, 2) / 3.0;
const Eigen::Vector3d kT2 = kN.cross(kT1);

ContactGeometry geometry(const Eigen::Vector3d& v_i, const Eigen::Vector3d& w_i,
                         const Eigen::Vector3d& w_j) {
  return sphere_contact(kXi, kXj, kRi, kRj, v_i, Eigen::Vector3d::Zero(), w_i, w_j,
                        sqrt_reduced_mass(mass(kRi), mass(kRj)));
}

void expect_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance,
                 const char* what) {
  EXPECT_LT((a - b).norm(), tolerance) << what << ": " << a.transpose() << " vs " << b.transpose();
}

TEST(ContactModel, GeometryOfUnequalGrains) {
  const ContactGeometry g =
      geometry(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  const double d = kRi + kRj - 1e-4;
  expect_near(g.n, kN, 1e-15, "n");
  EXPECT_NEAR(g.overlap, 1e-4, 1e-16);
  // The radical plane: l_i^2 - R_i^2 = l_j^2 - R_j^2, l_i + l_j = d.
  EXPECT_NEAR(g.l_i + g.l_j, d, 1e-17);  // d from rounded positions
  EXPECT_NEAR(g.l_i * g.l_i - kRi * kRi, g.l_j * g.l_j - kRj * kRj, 1e-19);
  EXPECT_NEAR(g.l_ij, 2 * g.l_i * g.l_j / (g.l_i + g.l_j), 1e-18);
  EXPECT_NEAR(g.sqrt_reduced_mass, std::sqrt(mass(kRi) * mass(kRj) / (mass(kRi) + mass(kRj))),
              1e-18);
}

TEST(ContactModel, NormalForceIsTheDampedSpring) {
  const ContactParameters p = parameters();
  const ContactModel model(p);
  const double m_red = mass(kRi) * mass(kRj) / (mass(kRi) + mass(kRj));
  const double c = dashpot_coefficient(p.k_n, p.restitution_n, m_red);
  EXPECT_NEAR(c, 2 * std::sqrt(m_red * p.k_n) * std::log(5) / std::hypot(M_PI, std::log(5)), 1e-15);
  for (double v_n : {-0.3, 0.0, 0.2}) {  // approaching, still, separating
    const ContactForces f = model.evaluate(geometry(v_n * kN, kZero, kZero), ContactHistory{}, kDt);
    const double expected = p.k_n * 1e-4 - c * v_n;
    EXPECT_NEAR(f.normal_force, expected, 1e-12 * std::abs(expected)) << "v_n " << v_n;
    expect_near(f.force_on_i, expected * kN, 1e-12, "force");
    expect_near(f.torque_on_i, Eigen::Vector3d::Zero(), 1e-18, "torque");
  }
  // Separating fast enough, the (unclipped) normal force is attractive.
  EXPECT_LT(model.evaluate(geometry(5.0 * kN, kZero, kZero), ContactHistory{}, kDt).normal_force,
            0);
}

TEST(ContactModel, SlidingBelowAndAtItsCap) {
  const ContactParameters p = parameters();
  const ContactModel model(p, p.mu_s, 0, 0);  // sliding alone
  const double m_red = mass(kRi) * mass(kRj) / (mass(kRi) + mass(kRj));
  const double c_t = dashpot_coefficient(p.k_t(), p.restitution_t, m_red);

  // Below the cap: one step of spring and the dashpot.
  const Eigen::Vector3d slow = 1e-3 * kT1;
  ContactGeometry g = geometry(slow, kZero, kZero);
  ContactForces f = model.evaluate(g, ContactHistory{}, kDt);
  const Eigen::Vector3d f_t = -p.k_t() * slow * kDt - c_t * slow;
  ASSERT_LT(f_t.norm(), p.mu_s * f.normal_force);
  expect_near(f.force_on_i - f.normal_force * kN, f_t, 1e-15, "F_t");
  expect_near(f.history.slide, slow * kDt, 1e-20, "spring");
  expect_near(f.torque_on_i, -g.l_i * kN.cross(f_t), 1e-18, "torque on i");
  expect_near(f.torque_on_j, -g.l_j * kN.cross(f_t), 1e-18, "torque on j");

  // At the cap: mu_s |F_n| against the sliding, spring rewritten to match.
  const Eigen::Vector3d fast = 0.5 * (kT1 + kT2);
  g = geometry(fast, kZero, kZero);
  ContactHistory before;
  before.slide = 1e-4 * kT2;
  f = model.evaluate(g, before, kDt);
  const Eigen::Vector3d ft = f.force_on_i - f.normal_force * kN;
  EXPECT_NEAR(ft.norm(), p.mu_s * std::abs(f.normal_force), 1e-15);
  EXPECT_LT(std::abs(ft.dot(kN)), 1e-15 * ft.norm());
  expect_near(-p.k_t() * f.history.slide - c_t * fast, ft, 1e-14,
              "spring matches the capped force");
  expect_near(f.torque_on_i, -g.l_i * kN.cross(ft), 1e-18, "torque on i");
  expect_near(f.torque_on_j, -g.l_j * kN.cross(ft), 1e-18, "torque on j");
}

TEST(ContactModel, RollingMomentBelowAndAtItsCap) {
  const ContactParameters p = parameters();
  const ContactModel model(p, p.mu_s, p.mu_r, 0);
  const double m_red = mass(kRi) * mass(kRj) / (mass(kRi) + mass(kRj));
  const double k_r = p.k_n * p.beta * p.beta / 4;
  const double c_r = dashpot_coefficient(p.k_n, p.restitution_n, m_red) * p.beta * p.beta / 4;
  const ContactGeometry g0 = geometry(kZero, kZero, kZero);
  // Pure rolling: l_i w_i + l_j w_j = 0, w perpendicular to n.
  const Eigen::Vector3d w_i = 40 * kT1, w_j = -(g0.l_i / g0.l_j) * w_i;
  const ContactGeometry g = geometry(-0.1 * kN, w_i, w_j);
  ASSERT_LT(g.v_t.norm(), 1e-15);
  const Eigen::Vector3d v_r = g.l_i * w_i.cross(kN) - g.l_j * w_j.cross(kN);

  // First step: the spring stretched by v_r dt, and the dashpot.
  ContactForces f = model.evaluate(g, ContactHistory{}, kDt);
  expect_near(f.force_on_i, f.normal_force * kN, 1e-15, "no sliding force");
  const double cap = p.mu_r * p.beta * std::abs(f.normal_force);
  const Eigen::Vector3d f_r = -(k_r * kDt + c_r) * v_r;
  ASSERT_LT(f_r.norm(), cap);
  Eigen::Vector3d moment = g.l_ij * kN.cross(f_r);
  expect_near(f.torque_on_i, moment, 1e-12 * moment.norm(), "rolling moment on i");
  expect_near(f.torque_on_j, -moment, 1e-12 * moment.norm(), "rolling moment on j");
  expect_near(f.history.roll, v_r * kDt, 1e-12 * v_r.norm() * kDt, "rolling spring");

  // A spring stretched past the cap: mu_r beta |F_n| against v_r.
  ContactHistory stretched;
  stretched.roll = 2 * cap / k_r * v_r.normalized();
  f = model.evaluate(g, stretched, kDt);
  moment = g.l_ij * kN.cross(-cap * v_r.normalized());
  expect_near(f.torque_on_i, moment, 1e-12 * moment.norm(), "capped rolling moment on i");
  expect_near(f.torque_on_j, -moment, 1e-12 * moment.norm(), "capped rolling moment on j");
  EXPECT_NEAR(f.torque_on_i.norm(), p.mu_r * p.beta * g.l_ij * std::abs(f.normal_force),
              1e-12 * moment.norm());
  // It resists: its power on the spins is negative.
  EXPECT_LT(f.torque_on_i.dot(w_i) + f.torque_on_j.dot(w_j), 0);
}

TEST(ContactModel, TwistingMomentBelowAndAtItsCap) {
  const ContactParameters p = parameters();
  const ContactModel model(p, p.mu_s, 0, p.mu_t);
  const double m_red = mass(kRi) * mass(kRj) / (mass(kRi) + mass(kRj));
  const double k_tw = p.k_t() * p.beta * p.beta / 2;
  const double c_tw = dashpot_coefficient(p.k_t(), p.restitution_t, m_red) * p.beta * p.beta / 2;
  for (double spin : {30.0, -30.0}) {
    SCOPED_TRACE("spin " + std::to_string(spin));
    const Eigen::Vector3d w_i = spin * kN, w_j = -0.5 * spin * kN;
    const ContactGeometry g = geometry(-0.1 * kN, w_i, w_j);
    const double v_tw = g.l_ij * (w_i - w_j).dot(kN);
    ContactForces f = model.evaluate(g, ContactHistory{}, kDt);
    expect_near(f.force_on_i, f.normal_force * kN, 1e-15, "no sliding force");
    const double cap = p.mu_t * p.mu_s * p.beta * std::abs(f.normal_force);
    const double f_tw = -(k_tw * kDt + c_tw) * v_tw;
    ASSERT_LT(std::abs(f_tw), cap);
    Eigen::Vector3d moment = g.l_ij * f_tw * kN;
    expect_near(f.torque_on_i, moment, 1e-12 * moment.norm(), "twisting moment on i");
    expect_near(f.torque_on_j, -moment, 1e-12 * moment.norm(), "twisting moment on j");

    ContactHistory stretched;
    stretched.twist = 2 * cap / k_tw * std::copysign(1.0, v_tw);
    f = model.evaluate(g, stretched, kDt);
    moment = -std::copysign(cap * g.l_ij, spin) * kN;
    expect_near(f.torque_on_i, moment, 1e-12 * moment.norm(), "capped twisting moment on i");
    expect_near(f.torque_on_j, -moment, 1e-12 * moment.norm(), "capped twisting moment on j");
  }
}

TEST(ContactModel, SpringTurnedOntoTheTangentPlaneKeepsItsLength) {
  const Eigen::Vector3d spring = 1e-5 * (kT1 + 0.3 * kN);
  const Eigen::Vector3d turned = onto_tangent_plane(spring, kN);
  EXPECT_NEAR(turned.norm(), spring.norm(), 1e-20);
  EXPECT_LT(std::abs(turned.dot(kN)), 1e-20);
  EXPECT_GT(turned.dot(kT1), 0);
  EXPECT_EQ(onto_tangent_plane(Eigen::Vector3d::Zero(), kN), Eigen::Vector3d::Zero());
  EXPECT_EQ(dashpot_coefficient(4000, 1.0, 1e-4), 0);
}

}  // namespace
}  // namespace granmem
