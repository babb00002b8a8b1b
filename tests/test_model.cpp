// The exact centrifuge model against independent routes: the nominal formulas with the terms they omit
// computed here, a finite difference of a pose built here from docs/physics.md section 3, docs/physics.md
// section 7's table typed in, first-order error effects, and invariants.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/model/nominal.hpp"
#include "support/independent_pose.hpp"
#include "support/rotations.hpp"

namespace gyrocal {
namespace {

using test_support::finite_difference_inputs;

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kDeg = kDegToRad;
constexpr double kSec = kArcsecToRad;

using testing::rx;
using testing::ry;
using testing::rz;

HarmonicSeries random_series(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-1, 1);
  HarmonicSeries h;
  for (int n = 1; n <= 3; ++n) h.terms.push_back({n, scale * std::abs(u(rng)), kPi * u(rng)});
  return h;
}

CentrifugeErrors random_errors(std::mt19937_64& rng, double angle_scale) {
  std::uniform_real_distribution<double> u(-1, 1);
  CentrifugeErrors e;
  const double a = angle_scale;
  e.base_tilt_x_rad = a * u(rng);
  e.base_tilt_y_rad = a * u(rng);
  e.main_perpendicularity_x_rad = a * u(rng);
  e.main_perpendicularity_y_rad = a * u(rng);
  e.main_wobble_x_rad = random_series(rng, a);
  e.main_wobble_y_rad = random_series(rng, a);
  e.main_runout_x_m = random_series(rng, 1e-4);
  e.main_runout_y_m = random_series(rng, 1e-4);
  e.radius_error_m = 1e-3 * u(rng);
  e.radius_stretch_m_per_rad2_s2 = 1e-6 * u(rng);
  e.counter_perpendicularity_x_rad = a * u(rng);
  e.counter_perpendicularity_y_rad = a * u(rng);
  e.counter_wobble_x_rad = random_series(rng, a);
  e.counter_wobble_y_rad = random_series(rng, a);
  e.counter_rate_mismatch_rad_s = 1e-5 * u(rng);
  e.position_perpendicularity_x_rad = a * u(rng);
  e.position_perpendicularity_z_rad = a * u(rng);
  e.position_wobble_x_rad = random_series(rng, a);
  e.position_wobble_z_rad = random_series(rng, a);
  e.position_angle_error_rad = a * u(rng);
  e.mount_misalignment_rad = a * Vector3d(u(rng), u(rng), u(rng));
  e.lever_arm_m = 0.05 * Vector3d(u(rng), u(rng), u(rng));
  e.counter_angle_error_rad = a * u(rng);
  return e;
}

TEST(ExactModel, AgreesWithFiniteDifferenceOfThePoseForRandomErrors) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 60; ++trial) {
    // Realistic (arcsec) errors and gross ones (degrees) that make every nonlinearity of the chain count.
    const double angle_scale = trial % 2 == 0 ? 20 * kSec : 2 * kDeg;
    Site site;
    site.latitude_rad = 80 * kDeg * u(rng);
    CentrifugeGeometry geo;
    geo.radius_m = 0.5 + std::abs(u(rng));
    geo.heading_rad = kPi * u(rng);
    geo.initial_main_angle_rad = kPi * u(rng);
    const CentrifugeModel m(site, geo, random_errors(rng, angle_scale));
    const double omega = 10 * u(rng);  // both senses
    const double beta = kPi * u(rng);
    const double t = 50 * std::abs(u(rng));
    const SensorInputs exact = exact_inputs(m, spinning_joint_state(m, omega, beta, t));
    const SensorInputs fd = finite_difference_inputs(m, omega, beta, t);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(exact.rate_rad_s[k], fd.rate_rad_s[k], 1e-9) << "trial " << trial << " axis " << k;
      EXPECT_NEAR(exact.specific_force_g[k], fd.specific_force_g[k], 1e-9)
          << "trial " << trial << " axis " << k;
    }
  }
}

TEST(ExactModel, AgreesWithFiniteDifferenceWhileTheMainAxisAcceleratesAndThePlatformTurns) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    CentrifugeGeometry geo;
    geo.initial_main_angle_rad = kPi * u(rng);
    const CentrifugeModel m(Site{}, geo, random_errors(rng, 1 * kDeg));
    const double omega = 5 * u(rng), accel = 2 * u(rng), beta = kPi * u(rng), t = 3 * std::abs(u(rng));
    const double beta_rate = 0.2 * u(rng);
    // The joints as the machine drives them: psi_r = -theta + psi0 + delta_omega*t.
    JointState j;
    j.main_angle_rad = geo.initial_main_angle_rad + omega * t + accel * t * t / 2;
    j.main_rate_rad_s = omega + accel * t;
    j.main_accel_rad_s2 = accel;
    j.counter_angle_rad = -j.main_angle_rad + geo.heading_rad + m.errors().counter_rate_mismatch_rad_s * t;
    j.counter_rate_rad_s = -j.main_rate_rad_s + m.errors().counter_rate_mismatch_rad_s;
    j.counter_accel_rad_s2 = -accel;
    j.position_angle_rad = beta + beta_rate * t;
    j.position_rate_rad_s = beta_rate;
    const SensorInputs exact = exact_inputs(m, j);
    const SensorInputs fd = finite_difference_inputs(m, omega, beta, t, accel, beta_rate);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(exact.rate_rad_s[k], fd.rate_rad_s[k], 1e-9) << "trial " << trial << " axis " << k;
      EXPECT_NEAR(exact.specific_force_g[k], fd.specific_force_g[k], 1e-9)
          << "trial " << trial << " axis " << k;
    }
  }
}

// Gyro axes I, O, S in G for a perfect machine at heading psi and position beta (docs/physics.md section 2).
Matrix3d nominal_axes(double psi, double beta) {
  Matrix3d a;
  a.col(0) = Vector3d(std::cos(beta) * std::cos(psi), std::cos(beta) * std::sin(psi), std::sin(beta));
  a.col(1) = Vector3d(-std::sin(psi), std::cos(psi), 0);
  a.col(2) = a.col(0).cross(a.col(1));
  return a;
}

TEST(ExactModel, PerfectMachineEqualsNominalPlusTheTermsTheSeedOmits) {
  for (double omega : {9.9, -9.9, 3.0, -0.5}) {
    for (double psi0 : {0.0, 0.7}) {
      Site site;
      CentrifugeGeometry geo;
      geo.heading_rad = psi0;
      geo.initial_main_angle_rad = 0.3;
      const CentrifugeModel m(site, geo, CentrifugeErrors{});
      for (double beta : {0.0, 0.4, kPi / 2, kPi, 4.0}) {
        for (double t : {0.0, 0.13, 1.7, 33.0}) {
          const JointState j = spinning_joint_state(m, omega, beta, t);
          const SensorInputs ex = exact_inputs(m, j);
          const NominalInputs no = nominal_inputs(m, j, false);
          // Omitted by section 5: the vertical Coriolis term 2*omega*R0*we*cos(lat)*cos(theta)/g along Up,
          // and the Earth's centripetal term we x (we x p); both projected on the gyro axes here.
          const double th = j.main_angle_rad, r0 = geo.radius_m, g = site.gravity_m_s2;
          const Vector3d we = site.earth_rate_g();
          const Vector3d p = r0 * Vector3d(std::cos(th), std::sin(th), 0);
          const Vector3d extra_g =
              (Vector3d(0, 0,
                        2 * omega * r0 * site.earth_rate_rad_s * std::cos(site.latitude_rad) * std::cos(th)) +
               we.cross(we.cross(p))) /
              g;
          const Vector3d extra = nominal_axes(psi0, beta).transpose() * extra_g;
          const double scale = std::abs(omega * omega * r0 / g) + 1;
          EXPECT_NEAR(ex.specific_force_g[0], no.a_I_g + extra[0], 1e-12 * scale);
          EXPECT_NEAR(ex.specific_force_g[1], no.a_O_g + extra[1], 1e-12 * scale);
          EXPECT_NEAR(ex.specific_force_g[2], no.a_S_g + extra[2], 1e-12 * scale);
          EXPECT_NEAR(ex.rate_rad_s[0], no.omega_I_rad_s, 1e-12 * site.earth_rate_rad_s);
          // The vertical Coriolis term is as large as docs/physics.md section 5 says (1.1e-4 g at 10 g).
          if (omega == 9.9 && t == 0.0 && beta == 0.0 && psi0 == 0.0) {
            EXPECT_NEAR(extra_g.z() / std::cos(th), 1.1e-4, 0.05e-4);
          }
        }
      }
    }
  }
}

// docs/physics.md section 7, typed in: beta, gamma (deg) and the coefficients of (a_I, a_O, a_S) on (Ar, 1)
// and of omega_I on (k1*omega, k2*omega, Omega_N, Omega_U).
struct TableRow {
  double beta_deg, gamma_deg;
  double ai_ar, ai_1, ao_ar, as_ar, as_1;
  double k1, k2, on, ou;
};
constexpr TableRow kTable[16] = {
    {0, 0, -1, 0, 0, 0, 1, 1, 0, 1, 0},      {0, 180, 1, 0, 0, 0, 1, -1, 0, 1, 0},
    {0, 90, 0, 0, -1, 0, 1, 0, -1, 1, 0},    {0, 270, 0, 0, 1, 0, 1, 0, 1, 1, 0},
    {180, 0, 1, 0, 0, 0, -1, -1, 0, -1, 0},  {180, 180, -1, 0, 0, 0, -1, 1, 0, -1, 0},
    {180, 90, 0, 0, -1, 0, -1, 0, 1, -1, 0}, {180, 270, 0, 0, 1, 0, -1, 0, -1, -1, 0},
    {90, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1},      {90, 180, 0, 1, 0, -1, 0, 0, 0, 0, 1},
    {90, 90, 0, 1, -1, 0, 0, 0, 0, 0, 1},    {90, 270, 0, 1, 1, 0, 0, 0, 0, 0, 1},
    {270, 0, 0, -1, 0, -1, 0, 0, 0, 0, -1},  {270, 180, 0, -1, 0, 1, 0, 0, 0, 0, -1},
    {270, 90, 0, -1, -1, 0, 0, 0, 0, 0, -1}, {270, 270, 0, -1, 1, 0, 0, 0, 0, 0, -1},
};

TEST(ExactModel, ReproducesTheSixteenPositionTable) {
  Scenario s;  // default geometry and site; machine errors chosen below
  s.errors.counter_perpendicularity_x_rad = 3 * kSec;
  s.errors.counter_perpendicularity_y_rad = -2 * kSec;
  s.errors.counter_rate_mismatch_rad_s = 2e-6;
  const CentrifugeModel m = s.model();
  const double omega = s.centrifuge.rate_rad_s, g = s.site.gravity_m_s2, r0 = s.centrifuge.radius_m;
  const double lat = s.site.latitude_rad, we = s.site.earth_rate_rad_s;
  const double ar = omega * r0 * (omega + 2 * we * std::sin(lat)) / g;
  const double k1 = 2 * kSec, k2 = 3 * kSec;  // k1 = -perp_y, k2 = perp_x
  const double on = we * std::cos(lat), ou = 2e-6 + we * std::sin(lat);
  const double vertical_coriolis = 2 * omega * r0 * we * std::cos(lat) / g;
  for (const TableRow& row : kTable) {
    const double beta = row.beta_deg * kDeg, gamma = row.gamma_deg * kDeg;
    const double t = time_at_gamma(m, omega, gamma, 3);
    const SensorInputs in = exact_inputs(m, spinning_joint_state(m, omega, beta, t));
    // The table's specific force, plus the vertical Coriolis term along Up (cos gamma at these positions);
    // the platform's 3" tilt moves the components by up to 3" * Ar.
    const double vc = vertical_coriolis * std::cos(gamma);
    const double tilt = 4 * kSec * (ar + 1);
    EXPECT_NEAR(in.specific_force_g[0], row.ai_ar * ar + row.ai_1 + vc * std::sin(beta), tilt)
        << row.beta_deg;
    EXPECT_NEAR(in.specific_force_g[1], row.ao_ar * ar, tilt) << row.beta_deg << " " << row.gamma_deg;
    EXPECT_NEAR(in.specific_force_g[2], row.as_ar * ar + row.as_1 + vc * std::cos(beta), tilt)
        << row.beta_deg;
    // omega_I to first order in the errors: the remainder is of order tilt^2 * omega + tilt * Earth rate,
    // 5e-9 rad/s here, against k*omega terms of 1.4e-4 rad/s.
    const double omega_i = row.k1 * k1 * omega + row.k2 * k2 * omega + row.on * on + row.ou * ou;
    const double remainder = (k1 * k1 + k2 * k2) * omega + (k1 + k2) * we;
    EXPECT_NEAR(in.rate_rad_s[0], omega_i, remainder) << row.beta_deg << " " << row.gamma_deg;
  }
}

TEST(ExactModel, CounterPlatformTiltAndRateMismatchShiftOmegaIAsTheSeedSays) {
  const Scenario s;
  const CentrifugeModel perfect(s.site, s.centrifuge, CentrifugeErrors{});
  const double omega = 9.9;
  for (double px : {0.0, 5 * kSec, -7 * kSec}) {
    for (double py : {0.0, 4 * kSec, -6 * kSec}) {
      CentrifugeErrors e;
      e.counter_perpendicularity_x_rad = px;
      e.counter_perpendicularity_y_rad = py;
      const CentrifugeModel tilted(s.site, s.centrifuge, e);
      for (const TableRow& row : kTable) {
        const double beta = row.beta_deg * kDeg, gamma = row.gamma_deg * kDeg;
        const double t = time_at_gamma(perfect, omega, gamma, 0);
        const double shift =
            exact_inputs(tilted, spinning_joint_state(tilted, omega, beta, t)).rate_rad_s[0] -
            exact_inputs(perfect, spinning_joint_state(perfect, omega, beta, t)).rate_rad_s[0];
        const double k1 = -py, k2 = px;
        const double expected = (k1 * std::cos(gamma) - k2 * std::sin(gamma)) * omega * std::cos(beta);
        // First order in the tilt: the remainder is of order tilt^2 * omega and tilt * Earth rate.
        const double remainder = (px * px + py * py) * omega + (std::abs(px) + std::abs(py)) * 7.3e-5;
        EXPECT_NEAR(shift, expected, remainder) << px << " " << py;
      }
    }
  }
  // delta omega alone: omega_I shifts by delta_omega * sin(beta).
  CentrifugeErrors e;
  e.counter_rate_mismatch_rad_s = 3e-6;
  const CentrifugeModel drifting(s.site, s.centrifuge, e);
  for (double beta : {0.0, 0.5, kPi / 2, kPi, 3 * kPi / 2}) {
    for (double t : {0.0, 1.0, 10.0}) {
      const double shift =
          exact_inputs(drifting, spinning_joint_state(drifting, omega, beta, t)).rate_rad_s[0] -
          exact_inputs(perfect, spinning_joint_state(perfect, omega, beta, t)).rate_rad_s[0];
      EXPECT_NEAR(shift, 3e-6 * std::sin(beta), 1e-12);
    }
  }
}

TEST(ExactModel, StaticMainAxisTiltShiftsOmegaIOnlyThroughTheEarthRate) {
  const Scenario s;
  const CentrifugeModel perfect(s.site, s.centrifuge, CentrifugeErrors{});
  const double tilt = 10 * kSec;
  for (int which = 0; which < 4; ++which) {
    CentrifugeErrors e;
    (which == 0   ? e.main_perpendicularity_x_rad
     : which == 1 ? e.main_perpendicularity_y_rad
     : which == 2 ? e.base_tilt_x_rad
                  : e.base_tilt_y_rad) = tilt;
    const CentrifugeModel tilted(s.site, s.centrifuge, e);
    for (double omega : {9.9, -5.0}) {
      for (const TableRow& row : kTable) {
        const double t = time_at_gamma(perfect, omega, row.gamma_deg * kDeg, 1);
        const double beta = row.beta_deg * kDeg;
        const double shift =
            exact_inputs(tilted, spinning_joint_state(tilted, omega, beta, t)).rate_rad_s[0] -
            exact_inputs(perfect, spinning_joint_state(perfect, omega, beta, t)).rate_rad_s[0];
        // A tilt of the whole machine turns the gyro by at most `tilt`; only the Earth rate's projection
        // moves.
        EXPECT_LE(std::abs(shift), s.site.earth_rate_rad_s * tilt * 1.001) << which;
      }
    }
  }
}

TEST(ExactModel, MountMisalignmentRotatesBothVectorsRigidly) {
  std::mt19937_64 rng(3);
  const Scenario s = default_scenario();
  CentrifugeErrors e = s.errors;
  e.mount_misalignment_rad = Vector3d(40, -25, 60) * kSec;
  const CentrifugeModel aligned(s.site, s.centrifuge, s.errors), misaligned(s.site, s.centrifuge, e);
  const Matrix3d mount =
      rz(e.mount_misalignment_rad.z()) * ry(e.mount_misalignment_rad.y()) * rx(e.mount_misalignment_rad.x());
  EXPECT_NEAR((mount.transpose() * mount - Matrix3d::Identity()).norm(), 0, 1e-15);
  std::uniform_real_distribution<double> u(0, 100);
  for (int k = 0; k < 20; ++k) {
    const double t = u(rng), beta = u(rng);
    const SensorInputs a = exact_inputs(aligned, spinning_joint_state(aligned, 9.9, beta, t));
    const SensorInputs b = exact_inputs(misaligned, spinning_joint_state(misaligned, 9.9, beta, t));
    EXPECT_NEAR((b.rate_rad_s - mount.transpose() * a.rate_rad_s).norm(), 0, 1e-15);
    EXPECT_NEAR((b.specific_force_g - mount.transpose() * a.specific_force_g).norm(), 0, 1e-13);
    EXPECT_NEAR(b.specific_force_g.norm(), a.specific_force_g.norm(), 1e-13);
  }
}

TEST(ExactModel, SpecificForceMagnitudeIsTheRadialAndVerticalLevels) {
  // Perfect machine, Earth rate off: |f| = sqrt(A^2 + 1) whatever beta and gamma, for either sense.
  Site site;
  site.earth_rate_rad_s = 0;
  const CentrifugeModel m(site, CentrifugeGeometry{}, CentrifugeErrors{});
  for (double omega : {9.9, -9.9, 2.0}) {
    const double a = omega * omega * 1.0 / site.gravity_m_s2;
    for (double beta : {0.0, 1.0, 2.5})
      for (double t : {0.0, 0.37, 12.0})
        EXPECT_NEAR(exact_inputs(m, spinning_joint_state(m, omega, beta, t)).specific_force_g.norm(),
                    std::sqrt(a * a + 1), 1e-13);
  }
}

TEST(ExactModel, TimeAtGammaFallsInTheRequestedRevolution) {
  const Scenario s = default_scenario();
  const CentrifugeModel m = s.model();
  for (double omega : {9.9, -4.0}) {
    const double period = 2 * kPi / std::abs(omega);
    for (int rev : {0, 1, 57}) {
      for (double gamma_deg : {0.0, 90.0, 180.0, 270.0, 359.0}) {
        const double t = time_at_gamma(m, omega, gamma_deg * kDeg, rev);
        EXPECT_GE(t, rev * period);
        EXPECT_LT(t, (rev + 1) * period + 1e-9);
        const double gamma = spinning_joint_state(m, omega, 0, t).gamma_rad();
        EXPECT_NEAR(std::remainder(gamma - gamma_deg * kDeg, 2 * kPi), 0, 1e-9);
      }
    }
  }
}

TEST(GyroModel, OutputIsRateInDegPerHourPlusDrift) {
  DriftCoefficients c = default_scenario().gyro;
  const Vector3d f(2.0, -3.0, 0.5);
  const double omega_i = 1e-4;
  // eq. 6 written out term by term.
  const double expected = omega_i * 180 / kPi * 3600 + 1.0 + 0.5 * 2 + 0.3 * -3 + -0.4 * 0.5 + 0.05 * 4 +
                          0.03 * 9 + -0.02 * 0.25 + 0.01 * 2 * -3 + 0.02 * 2 * 0.5 + -0.015 * -3 * 0.5;
  EXPECT_NEAR(gyro_output_deg_h(c, omega_i, f), expected, 1e-12);
}

}  // namespace
}  // namespace gyrocal
