// The model extensions that real machines and drives add to the paper's model (docs/model-extensions.md):
// rotor-frame flux harmonics, cross-saturation and a command delay of whole and fractional periods,
// each against an answer computed here independently (numerical derivatives, brute-force maxima,
// hand-indexed command histories).
#include <gtest/gtest.h>

#include <cmath>

#include "rpem/core/conditioner.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

constexpr double kSampleOmega = 150.0;  // electrical speed of the test samples [rad/s]

DriveSample dq_sample(std::int64_t t_ns, double theta, const Vec2& u_dq_V, const Vec2& i_dq_A) {
  DriveSample s;
  s.t_ns = t_ns;
  s.theta_el_rad = theta;
  s.omega_el_rad_s = kSampleOmega;
  s.u_dc_V = 565.0;
  s.voltage_frame = s.current_frame = Frame::kDq;
  s.u_V = Vec3(u_dq_V[0], u_dq_V[1], 0.0);
  s.i_A = Vec3(i_dq_A[0], i_dq_A[1], 0.0);
  return s;
}

/// The interval's end voltage with and without the extensions, from two samples at θ0 and θ1.
Vec2 end_voltage_change_pu(const ModelExtensions& x, double theta0, double theta1, const Vec2& i_dq_A) {
  const PerUnitBase b = test::paper_base();
  SampleConditioner with(b, test::paper_machine_pu(), x), without(b, test::paper_machine_pu(), {});
  const Vec2 u(40.0, 180.0);
  (void)with.condition(dq_sample(0, theta0, u, i_dq_A));
  (void)without.condition(dq_sample(0, theta0, u, i_dq_A));
  const EstimatorSample a = with.condition(dq_sample(125'000, theta1, u, i_dq_A));
  const EstimatorSample n = without.condition(dq_sample(125'000, theta1, u, i_dq_A));
  return a.interval.u_end_pu - n.interval.u_end_pu;
}

TEST(FluxHarmonic, InducedVoltageIsTheAngleDerivativeOfTheFluxPlusItsRotation) {
  // e_h = ω·(∂ψ_h/∂ϑ + J·ψ_h): the derivative here by central differences of ψ_h itself.
  const PerUnitBase b = test::paper_base();
  for (std::size_t j = 0; j < kFluxHarmonicOrders.size(); ++j) {
    ModelExtensions x;
    x.flux_harmonics[j] = {0.012, -0.02, 0.03, 0.007};
    const FluxHarmonic& h = x.flux_harmonics[j];
    const int order = kFluxHarmonicOrders[j];
    auto psi = [&](double th) {
      return Vec2(h.d_cos_Wb * std::cos(order * th) + h.d_sin_Wb * std::sin(order * th),
                  h.q_cos_Wb * std::cos(order * th) + h.q_sin_Wb * std::sin(order * th));
    };
    const double theta = 0.83, step = 1e-6;
    const Vec2 dpsi = (psi(theta + step) - psi(theta - step)) / (2.0 * step);
    const Vec2 e_V = kSampleOmega * (dpsi + Vec2(-psi(theta)[1], psi(theta)[0]));
    const Vec2 change = end_voltage_change_pu(x, 0.8, theta, Vec2(-1.0, 3.0));
    EXPECT_LT((change * b.voltage_V + e_V).norm(), 1e-6 * e_V.norm()) << "order " << order;  // taken from u
  }
}

TEST(FluxHarmonic, AmplitudeIsTheLargestFluxOverARevolution) {
  const FluxHarmonic h{0.012, -0.02, 0.03, 0.007};
  double largest = 0.0;
  for (int k = 0; k < 100000; ++k) {
    const double x = 2.0 * kPi * k / 100000;
    largest = std::max(largest, std::hypot(h.d_cos_Wb * std::cos(x) + h.d_sin_Wb * std::sin(x),
                                           h.q_cos_Wb * std::cos(x) + h.q_sin_Wb * std::sin(x)));
  }
  EXPECT_NEAR(h.amplitude_Wb(), largest, 1e-9);
  EXPECT_DOUBLE_EQ((FluxHarmonic{0.03, 0.0, 0.0, 0.03}).amplitude_Wb(), 0.03);  // a circle
}

TEST(FluxHarmonic, MultipleRotationMatchesLibm) {
  for (double th : {-3.0, -0.4, 0.0, 0.9, 2.7}) {
    for (int n : {0, 1, 5, 6, 7, 12, 13}) {
      const Rotation r = multiple(Rotation::of(th), n);
      EXPECT_NEAR(r.cos, std::cos(n * th), 1e-13);
      EXPECT_NEAR(r.sin, std::sin(n * th), 1e-13);
    }
  }
}

TEST(FluxHarmonic, AverageOutOfTheSteadyState) {
  ModelExtensions x;
  x.flux_harmonics[0] = {0.02, 0.0, 0.0, 0.02};
  const PerUnitBase b = test::paper_base();
  const SampleConditioner with(b, test::paper_machine_pu(), x), without(b, test::paper_machine_pu(), {});
  const DriveSample s = dq_sample(0, 0.3, Vec2(40.0, 180.0), Vec2(-1.0, 3.0));
  EXPECT_EQ((with.steady_state(s).u_pu - without.steady_state(s).u_pu).norm(), 0.0);
}

TEST(CrossSaturation, TheSecondTermAddsCTwoIdToBothHalves) {
  // ψ_d += c₂·i_d·i_q², ψ_q += c₂·i_d²·i_q: x_q moves by c₂·i_d², the q voltage by ω·c₂·i_d·i_q².
  const PerUnitBase b = test::paper_base();
  const MachinePu m = test::paper_machine_pu();
  const double c2 = 3e-4;  // H/A²
  ModelExtensions x;
  x.cross_coupling_H_per_A2 = c2;
  const Vec2 i_A(-4.0, 6.0);
  SampleConditioner cond(b, m, x);
  const EstimatorSample out = cond.condition(dq_sample(0, 0.3, Vec2(40.0, 180.0), i_A));
  EXPECT_NEAR(out.x_q_pu * b.inductance_H, m.x_q_pu * b.inductance_H + c2 * i_A[0] * i_A[0], 1e-15);
  const Vec2 change = end_voltage_change_pu(x, 0.3, 0.32, i_A);
  EXPECT_NEAR(change[1] * b.voltage_V, -kSampleOmega * c2 * i_A[0] * i_A[1] * i_A[1], 1e-12);
}

TEST(CrossSaturation, LqFollowsIdAndTheDAxisFluxFollowsTheLoad) {
  // ψ_d = L_d·i_d + ψm + (c/2)·i_q², ψ_q = (L_q + c·i_d)·i_q: the apparent x_q moves by c·i_d, and the
  // extra d-axis flux induces ω·(c/2)·i_q² on the q axis (J·[Δψ_d, 0]).
  const PerUnitBase b = test::paper_base();
  const MachinePu m = test::paper_machine_pu();
  const double c = -2e-3;  // H/A
  ModelExtensions x;
  x.cross_coupling_H_per_A = c;
  const Vec2 i_A(-4.0, 6.0);
  SampleConditioner cond(b, m, x);
  const EstimatorSample out = cond.condition(dq_sample(0, 0.3, Vec2(40.0, 180.0), i_A));
  EXPECT_NEAR(out.x_d_pu, m.x_d_pu, 1e-15);
  EXPECT_NEAR(out.x_q_pu * b.inductance_H, m.x_q_pu * b.inductance_H + c * i_A[0], 1e-15);
  const Vec2 change = end_voltage_change_pu(x, 0.3, 0.32, i_A);
  EXPECT_NEAR(change[0], 0.0, 1e-15);
  EXPECT_NEAR(change[1] * b.voltage_V, -kSampleOmega * 0.5 * c * i_A[1] * i_A[1], 1e-12);
  // In the steady state too (it is no harmonic).
  const SteadyStateInputs ss = cond.steady_state(dq_sample(0, 0.3, Vec2(40.0, 180.0), i_A));
  EXPECT_NEAR(ss.u_pu[1] * b.voltage_V, 180.0 - kSampleOmega * 0.5 * c * i_A[1] * i_A[1], 1e-12);
  EXPECT_NEAR(ss.x_q_pu, out.x_q_pu, 1e-15);
}

TEST(Delay, WholeAndFractionalPeriodsTakeTheCommandIssuedThatLongBefore) {
  // u_k issued at sample k (dq at θ = 0, so stator = rotor frame). With delay (m + f)·T the interval
  // [k−1, k] sees (1 − f)·u_{k−1−m} + f·u_{k−2−m}; before the first sample the first command stands in.
  const PerUnitBase b = test::paper_base();
  for (double periods : {0.0, 0.4, 1.0, 2.0, 2.4, 3.7}) {
    ModelExtensions x;
    x.delay_s = periods * 125e-6;
    SampleConditioner c(b, test::paper_machine_pu(), x);
    std::vector<double> issued;
    for (int k = 0; k < 12; ++k) {
      issued.push_back(10.0 * k * k + 3.0);
      const EstimatorSample out = c.condition(dq_sample(k * 125'000LL, 0.0, Vec2(issued.back(), 0.0), Vec2::Zero()));
      if (k == 0) continue;
      const int m = static_cast<int>(periods);
      const double f = periods - m;
      auto at = [&](int j) { return issued[static_cast<std::size_t>(std::max(j, 0))]; };
      const double expected = (1.0 - f) * at(k - 1 - m) + f * at(k - 2 - m);
      EXPECT_NEAR(out.interval.u_start_pu[0] * b.voltage_V, expected, 1e-9) << periods << " periods, k = " << k;
    }
  }
}

TEST(Delay, AGapForgetsTheCommandsBeforeIt) {
  const PerUnitBase b = test::paper_base();
  ModelExtensions x;
  x.delay_s = 2.0 * 125e-6;
  SampleConditioner c(b, test::paper_machine_pu(), x);
  for (int k = 0; k < 5; ++k) (void)c.condition(dq_sample(k * 125'000LL, 0.0, Vec2(100.0, 0.0), Vec2::Zero()));
  DriveSample after = dq_sample(10 * 125'000LL, 0.0, Vec2(7.0, 0.0), Vec2::Zero());
  after.gap_before = true;
  EXPECT_TRUE(c.condition(after).resync);
  const EstimatorSample next = c.condition(dq_sample(11 * 125'000LL, 0.0, Vec2(9.0, 0.0), Vec2::Zero()));
  EXPECT_NEAR(next.interval.u_start_pu[0] * b.voltage_V, 7.0, 1e-12);  // not the 100 V from before the gap
}

}  // namespace
}  // namespace rpem::core
