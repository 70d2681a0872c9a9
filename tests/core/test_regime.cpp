// The regime classifier (core/regime.hpp, docs/derivations.md §13): each rule's threshold recomputed here
// from its derivation and checked from both sides (1 % inside: the first class; 1 % outside: the other),
// on samples made from the steady-state dq equations of a VESC-class outrunner; the noise and resolution it
// measures; and seeded runs of locked, steady, noisy data whose exclusions stay within the false rate.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "rpem/core/frames.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/core/settings.hpp"
#include "support/outrunner_machine.hpp"
#include "support/paper_machine.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

/// The outrunner's classifier configuration with the data's resolution given: noise-free probes then
/// see σ² = q²/12 exactly (the measured noise of identical samples is zero).
struct Outrunner {
  MachineSi machine = test::outrunner_machine_si();
  EstimatorSettings settings = test::outrunner_settings();
  PerUnitBase base = test::outrunner_base();
  MachinePu nominal = to_pu(base, machine);
  RegimeConfig config() const { return make_regime_config(base, machine, settings); }
  Outrunner() {
    settings.regimes.voltage_resolution_V = 0.01;  // VESC Tool writes volts with two decimals
  }
};

/// A sample at the machine's steady state for a rotor-frame current, in a frame `delta` ahead of the rotor.
RegimeInput steady(const MachinePu& plant, double n, const Vec2& i_frame, double delta = 0.0) {
  const Rotation to_rotor = Rotation::of(delta);
  const Vec2 i_rotor = inverse_park(i_frame, to_rotor);  // the frame's axes turned back by δ onto the rotor's
  const Vec2 u_rotor = steady_state_voltage(plant, n, i_rotor);
  RegimeInput in;
  in.u_pu = park(u_rotor, to_rotor);
  in.i_pu = i_frame;
  in.n_pu = n;
  in.u_reported_sq_pu = in.u_pu.squaredNorm();
  in.weight = Vec2::Ones();
  return in;
}

/// The j-th sample (0-based) of a contiguous chain ending at t_ns: the first starts the chain.
RegimeInput chain_sample(int j, std::int64_t t_ns, const Vec2& u, const Vec2& i, double n) {
  RegimeInput in;
  in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
  in.t_ns = t_ns;
  in.u_pu = u;
  in.i_pu = i;
  in.n_pu = n;
  in.u_reported_sq_pu = u.squaredNorm();
  return in;
}

/// The classification of `in` after three identical samples 10 ms apart (noise known and zero, slope zero).
Classification probe(const RegimeConfig& c, RegimeInput in) {
  RegimeClassifier k(c);
  Classification out;
  for (int j = 0; j < 4; ++j) {
    in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
    in.t_ns = (j + 1) * 10'000'000LL;
    out = k.step(in);
  }
  return out;
}

TEST(Regime, TheTwoDimensionalBoundHasTheOneDimensionalFalseRate) {
  // |v|²/σ² of a two-dimensional standard normal is χ²₂, P(χ²₂ > c) = e^{−c/2}: c₂ = −2·ln(erfc(z/√2)).
  for (double z : {2.0, 3.0, 4.0, 5.0}) {
    EXPECT_NEAR(std::exp(-0.5 * chi2_bound(z)) / std::erfc(z / std::sqrt(2.0)), 1.0, 1e-12) << z;
  }
  EXPECT_NEAR(chi2_bound(4.0), 19.3339, 1e-4);  // −2·ln(6.33425e-5)
}

TEST(Regime, RegimeOfTheBitsFollowsThePrecedence) {
  using namespace regime_bit;
  EXPECT_EQ(regime_of(0), Regime::kUnexcited);
  EXPECT_EQ(regime_of(kExcitesPsiM | kExcitesRs), Regime::kExcitesBoth);
  EXPECT_EQ(regime_of(kExcitesRs), Regime::kExcitesRs);
  EXPECT_EQ(regime_of(kTransient | kExcitesPsiM), Regime::kTransient);
  EXPECT_EQ(regime_of(kTransient | kNotLocked), Regime::kNotLocked);
  EXPECT_EQ(regime_of(kBridgeOff | kNotLocked | kTransient), Regime::kBridgeOff);
  EXPECT_EQ(regime_of(kInvalid | kBridgeOff), Regime::kInvalid);
  const Classification c = Classification::of(kTransient | kExcitesPsiM);
  EXPECT_TRUE(c.excluded());
  EXPECT_FALSE(c.excites_psi_m());  // an excluded sample excites nothing
  for (std::size_t k = 0; k < kRegimeCount; ++k) EXPECT_EQ(static_cast<std::size_t>(kRegimes[k].regime), k);
}

TEST(Regime, BridgeOffIsZeroVoltageAndCurrentWhereAModulatingBridgeWouldShortCircuit) {
  Outrunner s;
  s.settings.regimes.current_resolution_A = 0.1;
  const RegimeConfig c = s.config();
  // Freewheeling at speed: u reported 0, i within the current's noise. The boundary: |i|² = c₂·q_i²/12.
  const double sigma_i = c.resolution_pu[1] / std::sqrt(12.0);
  const double edge = std::sqrt(c.chi2) * sigma_i;
  auto freewheel = [&](double n, double i) {
    RegimeInput in;
    in.n_pu = n;
    in.i_pu = Vec2(0.6, 0.8) * i;
    in.weight = Vec2::Ones();
    return probe(c, in).regime;
  };
  EXPECT_EQ(freewheel(0.5, 0.99 * edge), Regime::kBridgeOff);
  EXPECT_NE(freewheel(0.5, 1.01 * edge), Regime::kBridgeOff);
  EXPECT_NE(freewheel(-0.5, 1.01 * edge), Regime::kBridgeOff);
  EXPECT_EQ(freewheel(-0.5, 0.0), Regime::kBridgeOff);
  // At standstill a modulating bridge at zero volts drives no current either: nothing tells them apart.
  EXPECT_NE(freewheel(0.0, 0.0), Regime::kBridgeOff);
  // Active short circuit: zero volts, the short-circuit current flows — the bridge modulates.
  RegimeInput asc = steady(s.nominal, 0.5, steady_state_current(s.nominal, 0.5, Vec2::Zero()));
  asc.u_pu.setZero();
  asc.u_reported_sq_pu = 0.0;
  EXPECT_FALSE(probe(c, asc).bits & regime_bit::kBridgeOff);
  EXPECT_FALSE(probe(c, asc).excluded());
}

TEST(Regime, LockIsTheBackEmfsDirectionWithinTheDerivedCone) {
  Outrunner s;
  const RegimeConfig c = s.config();
  const double n = 0.5, current = 0.5;
  // The outrunner has x_d = x_q: in a frame δ ahead of the rotor e = n·ψm·[sin δ, cos δ] exactly, so the
  // test |e_d| − tan δ_tol·e_q − B > z·σ turns at sin(δ* − δ_tol) = cos δ_tol·(B + z·σ/cos δ_tol)/(n·ψm), with
  // B = |n|·Δx·I + tan δ_tol·Δr·I (i = [0, I] in the frame) and σ² = q_u²/12·(1 + tan² δ_tol).
  const double tan_tol = std::tan(s.settings.regimes.angle_tolerance_rad);
  const double b = n * c.dx_q_pu * current + tan_tol * c.dr_pu * current;
  const double sigma_over_cos = c.resolution_pu[0] / std::sqrt(12.0) / std::cos(s.settings.regimes.angle_tolerance_rad);
  const double edge =
      s.settings.regimes.angle_tolerance_rad +
      std::asin(std::cos(s.settings.regimes.angle_tolerance_rad) * (b + c.z * sigma_over_cos) / (n * s.nominal.psi_m_pu));
  const Vec2 i(0.0, current);
  EXPECT_EQ(probe(c, steady(s.nominal, n, i, edge - 0.002)).regime, Regime::kExcitesPsiM);
  EXPECT_EQ(probe(c, steady(s.nominal, n, i, edge + 0.002)).regime, Regime::kNotLocked);
  EXPECT_EQ(probe(c, steady(s.nominal, n, i, -edge - 0.002)).regime, Regime::kNotLocked);
  EXPECT_GT(edge, s.settings.regimes.angle_tolerance_rad);
  EXPECT_LT(edge, 0.35);
  // Reversed (δ = π: the frame turned half a revolution), and an open-loop start-up's 80° lag.
  EXPECT_EQ(probe(c, steady(s.nominal, n, i, kPi)).regime, Regime::kNotLocked);
  EXPECT_EQ(probe(c, steady(s.nominal, -n, i, 80.0 * kPi / 180.0)).regime, Regime::kNotLocked);
  // The magnet's size does not matter: a machine with ψm 30 % off either way is locked.
  for (double scale : {0.7, 1.3}) {
    MachinePu plant = s.nominal;
    plant.psi_m_pu *= scale;
    EXPECT_FALSE(probe(c, steady(plant, n, i)).excluded()) << scale;
    EXPECT_FALSE(probe(c, steady(plant, -n, i)).excluded()) << scale;
  }
  // r_s anywhere in D_M and inductances within their tolerance: still locked.
  MachinePu plant = s.nominal;
  plant.r_s_pu = c.r_min_pu;
  plant.x_d_pu *= 1.25;
  plant.x_q_pu *= 0.75;
  EXPECT_FALSE(probe(c, steady(plant, n, Vec2(-0.3, 0.6))).excluded());
}

TEST(Regime, PsiMIsExcitedWhereItsTermStandsOutOfTheAveragedNoise) {
  Outrunner s;
  const RegimeConfig c = s.config();
  // i = 0: the term is |n|·ψ_min against N = σ_u = q_u/√12 as a gain γ averages it, h² = γ/(2 − γ).
  const double gamma = 1e-3;
  const double h = std::sqrt(gamma / (2.0 - gamma));
  const double edge = c.z * h * c.resolution_pu[0] / std::sqrt(12.0) / c.psi_min_pu;
  auto at = [&](double n) {
    RegimeInput in = steady(s.nominal, n, Vec2::Zero());
    in.weight = Vec2::Constant(gamma);
    return probe(c, in).regime;
  };
  EXPECT_EQ(at(1.01 * edge), Regime::kExcitesPsiM);
  EXPECT_EQ(at(0.99 * edge), Regime::kUnexcited);
  EXPECT_EQ(at(-1.01 * edge), Regime::kExcitesPsiM);
  EXPECT_GT(edge, 1e-5);
}

TEST(Regime, RsIsExcitedWhereItsDropStandsOutOfNoiseAndTheFluxsUncertainty) {
  Outrunner s;
  const RegimeConfig c = s.config();
  const double gamma = 1e-3;
  const double noise = std::sqrt(gamma / (2.0 - gamma)) * c.resolution_pu[0] / std::sqrt(12.0);
  auto at = [&](double n, double current) {
    RegimeInput in = steady(s.nominal, n, Vec2(0.0, current));
    in.weight = Vec2::Constant(gamma);
    return probe(c, in);
  };
  // Standstill: r_min·|i| > z·N.
  const double still = c.z * noise / c.r_min_pu;
  EXPECT_TRUE(at(0.0, 1.01 * still).bits & regime_bit::kExcitesRs);
  EXPECT_FALSE(at(0.0, 0.99 * still).bits & regime_bit::kExcitesRs);
  // At speed ψm's uncertainty inside D_M and the inductance's tolerance compete:
  // r_min·|i| − |n|·(Δψ + Δx·|i|) > z·N  ⇔  |i| > (z·N + |n|·Δψ)/(r_min − |n|·Δx).
  const double n = 2e-3;
  const double moving = (c.z * noise + n * c.dpsi_pu) / (c.r_min_pu - n * c.dx_q_pu);
  EXPECT_TRUE(at(n, 1.01 * moving).bits & regime_bit::kExcitesRs);
  EXPECT_FALSE(at(n, 0.99 * moving).bits & regime_bit::kExcitesRs);
  EXPECT_FALSE(at(-n, 0.99 * moving).bits & regime_bit::kExcitesRs);
  EXPECT_GT(moving, 10.0 * still);  // the flux's uncertainty, not the noise, sets it there
}

/// r_s' excitation edge at speed n from both sides: excited 1 % above `edge` (the current), not 1 % below.
template <typename At>
void expect_rs_edge(const At& at, const RegimeConfig& c, double n, double edge) {
  EXPECT_TRUE(at(c, n, 1.01 * edge).bits & regime_bit::kExcitesRs) << "n " << n << ", edge " << edge;
  EXPECT_FALSE(at(c, n, 0.99 * edge).bits & regime_bit::kExcitesRs) << "n " << n << ", edge " << edge;
}

// A sensorless frame (`angle_source: sensorless`): the lock test passes a frame error δ while
// sin(δ − δ_tol) ≤ a = cos δ_tol·(B_d + tan δ_tol·B_q + z·σ_L)/(|n|·ψ_min) (a frame turning with the rotor stays
// within δ_tol + π/2), and such an error adds |n|·ψ·2·sin(δ/2) to the magnet's voltage error: r_s is excited where
// r_min·|i| − |n|·(Δψ + 2·ψ_max·sin(δ_max/2) + Δx·|i|) > z·N. The edge found here by bisection on that form (its
// trigonometry, not the classifier's), checked from both sides at a speed where the lock test cannot judge the
// frame at the edge (a ≥ 1) and at one where it bounds it (a < 1); with a sensor the same samples keep the edge of
// the test above. An open-loop start-up 60° off at that low speed implies an r_s far off, which only the sensorless
// test refuses.
TEST(Regime, ASensorlessFramesRsIsExcitedOnlyBeyondTheFrameErrorTheLockTestLeaves) {
  const double gamma = 1e-3;
  // The outrunner as configured (D_M's r_s 12.5–50 mΩ: B_q = Δr·I hides any frame at r_s' edge, a ≥ 1) and with its
  // r_s commissioned to ±5 % (the test bounds the frame there, a < 1).
  bool judged = false, undecided = false;
  for (const double r_s_spread : {0.0, 0.05}) {
    Outrunner s;
    if (r_s_spread > 0.0) {
      s.settings.r_s_min_Ohm = s.machine.r_s_Ohm * (1.0 - r_s_spread);
      s.settings.r_s_max_Ohm = s.machine.r_s_Ohm * (1.0 + r_s_spread);
    }
    const RegimeConfig sensor = s.config();
    s.settings.regimes.sensorless = true;
    const RegimeConfig c = s.config();
    const double sigma_u = c.resolution_pu[0] / std::sqrt(12.0);  // σ_i = σ_n = 0: probes repeat one sample
    const double noise = std::sqrt(gamma / (2.0 - gamma)) * sigma_u;
    const double delta_tol = s.settings.regimes.angle_tolerance_rad, tan_tol = std::tan(delta_tol);
    const double sigma_lock = sigma_u * std::sqrt(1.0 + tan_tol * tan_tol);  // σ_L² = σ_ed² + tan² δ_tol·σ_eq²
    // i = [0, I]: B_d = |n|·Δx_q·I, B_q = Δr·I.
    const auto reach = [&](double n, double current) {
      return std::cos(delta_tol) * (n * c.dx_q_pu * current + tan_tol * c.dr_pu * current + c.z * sigma_lock) /
             (n * c.psi_min_pu);
    };
    const auto term = [&](double n, double current) {
      const double delta_max = delta_tol + std::asin(std::min(1.0, reach(n, current)));
      const double frame = 2.0 * c.psi_max_pu * std::sin(0.5 * delta_max);
      return c.r_min_pu * current - n * (c.dpsi_pu + frame + c.dx_q_pu * current) - c.z * noise;
    };
    const auto at = [&](const RegimeConfig& config, double n, double current) {
      RegimeInput in = steady(s.nominal, n, Vec2(0.0, current));
      in.weight = Vec2::Constant(gamma);
      return probe(config, in);
    };
    const double n = 2e-3;
    double lo = 0.0, hi = 50.0;
    ASSERT_LT(term(n, lo), 0.0);
    ASSERT_GT(term(n, hi), 0.0);
    for (int k = 0; k < 200; ++k) (term(n, 0.5 * (lo + hi)) > 0.0 ? hi : lo) = 0.5 * (lo + hi);
    const double edge = hi;
    SCOPED_TRACE(::testing::Message() << "r_s ±" << r_s_spread << ", edge " << edge << ", a " << reach(n, edge));
    (reach(n, edge) >= 1.0 ? undecided : judged) = true;
    expect_rs_edge(at, c, n, edge);
    EXPECT_FALSE(at(c, -n, 0.99 * edge).bits & regime_bit::kExcitesRs);
    // With a sensor the frame is the rotor's: the edge of the test above, below.
    const double measured = (c.z * noise + n * c.dpsi_pu) / (c.r_min_pu - n * c.dx_q_pu);
    EXPECT_LT(measured, 0.9 * edge);
    EXPECT_TRUE(at(sensor, n, 1.01 * measured).bits & regime_bit::kExcitesRs);
    EXPECT_FALSE(at(c, n, 1.01 * measured).bits & regime_bit::kExcitesRs);
    // At standstill no frame error reaches the voltage: the edge is the sensor's.
    expect_rs_edge(at, c, 0.0, c.z * noise / c.r_min_pu);
  }
  EXPECT_TRUE(judged);
  EXPECT_TRUE(undecided);

  // An open-loop start-up at 2·10⁻³ of base speed, the frame 45° ahead, the current along its q at three times the
  // sensor's edge: the lock test cannot judge it, r_s is excited with a sensor, and the r_s the q row implies,
  // (u_q − n·ψ̂)/I, is off by n·ψm·(cos δ − 1)/I — beyond the 5 % issue 23 asks of r_s. Sensorless: not excited.
  Outrunner s;
  const RegimeConfig sensor = s.config();
  s.settings.regimes.sensorless = true;
  const RegimeConfig c = s.config();
  const double noise = std::sqrt(gamma / (2.0 - gamma)) * c.resolution_pu[0] / std::sqrt(12.0);
  const double n = 2e-3, delta = kPi / 4.0;
  const double current = 3.0 * (c.z * noise + n * c.dpsi_pu) / (c.r_min_pu - n * c.dx_q_pu);
  RegimeInput open_loop = steady(s.nominal, n, Vec2(0.0, current), delta);
  open_loop.weight = Vec2::Constant(gamma);
  EXPECT_EQ(probe(sensor, open_loop).regime, Regime::kExcitesRs);
  EXPECT_EQ(probe(c, open_loop).regime, Regime::kUnexcited);
  const double implied = (open_loop.u_pu[1] - n * s.nominal.psi_m_pu) / current;
  EXPECT_NEAR(implied - s.nominal.r_s_pu, n * s.nominal.psi_m_pu * (std::cos(delta) - 1.0) / current,
              1e-3 * s.nominal.r_s_pu);
  EXPECT_GT(std::abs(implied / s.nominal.r_s_pu - 1.0), 0.05);
}

// A sensorless stall's rocking (docs/derivations.md §13, "A stall's rocking"): a window whose mean speed is zero while
// its reads show the rotor at speed. The frame's error acts at the speeds the window passed through: r_s is excited
// where r_min·|i| − n_reach·F > z·N, F the frame error's flux where the lock test cannot judge (at a zero mean speed,
// δ_max = δ_tol + π/2: F = ψ_max·√(2·(1 + sin δ_tol))). The edge from both sides; without reads (n_reach 0) the
// standstill edge; a sensor's frame unmoved by the reads; reads slower than the mean change nothing.
TEST(Regime, ARockingStallsReadsTakeTheFrameErrorWhereTheWindowsMeanHidesIt) {
  const double gamma = 1e-3;
  Outrunner s;
  const RegimeConfig sensor = s.config();
  s.settings.regimes.sensorless = true;
  const RegimeConfig c = s.config();
  const double noise = std::sqrt(gamma / (2.0 - gamma)) * c.resolution_pu[0] / std::sqrt(12.0);
  const double delta_tol = s.settings.regimes.angle_tolerance_rad;
  const double frame = c.psi_max_pu * std::sqrt(2.0 * (1.0 + std::sin(delta_tol)));
  const auto at = [&](const RegimeConfig& config, double n, double current, double reads) {
    RegimeInput in = steady(s.nominal, n, Vec2(0.0, current));
    in.weight = Vec2::Constant(gamma);
    in.n_reach_pu = reads;
    return probe(config, in);
  };
  const double reads = 2e-3;  // 84 erpm on the outrunner's base (42 000 erpm): a rocking rotor's read
  const double edge = (c.z * noise + reads * frame) / c.r_min_pu;
  const double standstill = c.z * noise / c.r_min_pu;
  ASSERT_GT(edge, 3.0 * standstill);
  EXPECT_TRUE(at(c, 0.0, 1.01 * edge, reads).bits & regime_bit::kExcitesRs) << "edge " << edge;
  EXPECT_FALSE(at(c, 0.0, 0.99 * edge, reads).bits & regime_bit::kExcitesRs) << "edge " << edge;
  EXPECT_TRUE(at(c, 0.0, 1.01 * standstill, 0.0).bits & regime_bit::kExcitesRs);
  EXPECT_TRUE(at(sensor, 0.0, 1.01 * standstill, reads).bits & regime_bit::kExcitesRs);
  // A window at its reads' speed or faster: the mean decides, as without them.
  for (const double n : {2e-3, -3e-3}) {
    EXPECT_EQ(at(c, n, 2.0 * edge, 0.5 * std::abs(n)).bits, at(c, n, 2.0 * edge, 0.0).bits) << "n " << n;
    EXPECT_EQ(at(c, n, 0.9 * edge, std::abs(n)).bits, at(c, n, 0.9 * edge, 0.0).bits) << "n " << n;
  }
}

// Hall sensors (`angle_source: hall`): below their speed the frame is within their own error δ_h of the rotor's, so
// r_s' frame term takes the smaller of the two bounds, δ_max = min(δ_tol + asin(min(1, a)), δ_h) — the edge found by
// bisection on that form and checked from both sides, where the Hall bound decides and where the lock test's does;
// above their speed (the observer's frame) the sensorless edge; at standstill the sensor's. The edge lies between
// a sensor's and a sensorless frame's wherever the Hall bound is the smaller.
TEST(Regime, HallSensorsBoundTheFrameErrorBelowTheirSpeed) {
  const double gamma = 1e-3, n = 2e-3;
  bool hall_decided = false, lock_decided = false;
  for (const double r_s_spread : {0.0, 0.05}) {
    for (const double hall_error : {kHallFrameErrorRad, 1.2}) {
      Outrunner s;
      if (r_s_spread > 0.0) {
        s.settings.r_s_min_Ohm = s.machine.r_s_Ohm * (1.0 - r_s_spread);
        s.settings.r_s_max_Ohm = s.machine.r_s_Ohm * (1.0 + r_s_spread);
      }
      s.settings.regimes.sensorless = true;
      const RegimeConfig sensorless = s.config();
      s.settings.regimes.hall_frame_error_rad = hall_error;
      s.settings.regimes.hall_below_speed_rad_s = 2.0 * n * s.base.omega_el_rad_s;
      const RegimeConfig c = s.config();
      s.settings.regimes.hall_below_speed_rad_s = 0.5 * n * s.base.omega_el_rad_s;
      const RegimeConfig observer = s.config();  // n is above the Hall sensors' speed: the observer's frame
      const double sigma_u = c.resolution_pu[0] / std::sqrt(12.0);  // σ_i = σ_n = 0: probes repeat one sample
      const double noise = std::sqrt(gamma / (2.0 - gamma)) * sigma_u;
      const double delta_tol = s.settings.regimes.angle_tolerance_rad, tan_tol = std::tan(delta_tol);
      const double sigma_lock = sigma_u * std::sqrt(1.0 + tan_tol * tan_tol);
      const auto reach = [&](double current) {  // i = [0, I]: B_d = |n|·Δx_q·I, B_q = Δr·I
        return std::cos(delta_tol) * (n * c.dx_q_pu * current + tan_tol * c.dr_pu * current + c.z * sigma_lock) /
               (n * c.psi_min_pu);
      };
      const auto lock_bound = [&](double current) { return delta_tol + std::asin(std::min(1.0, reach(current))); };
      const auto edge_of = [&](double cap) {
        const auto term = [&](double current) {
          const double frame = 2.0 * c.psi_max_pu * std::sin(0.5 * std::min(lock_bound(current), cap));
          return c.r_min_pu * current - n * (c.dpsi_pu + frame + c.dx_q_pu * current) - c.z * noise;
        };
        double lo = 0.0, hi = 50.0;
        EXPECT_LT(term(lo), 0.0);
        EXPECT_GT(term(hi), 0.0);
        for (int k = 0; k < 200; ++k) (term(0.5 * (lo + hi)) > 0.0 ? hi : lo) = 0.5 * (lo + hi);
        return hi;
      };
      const auto at = [&](const RegimeConfig& config, double speed, double current) {
        RegimeInput in = steady(s.nominal, speed, Vec2(0.0, current));
        in.weight = Vec2::Constant(gamma);
        return probe(config, in);
      };
      const double edge = edge_of(hall_error), open_edge = edge_of(kPi);
      const bool hall_smaller = hall_error < lock_bound(edge);
      SCOPED_TRACE(::testing::Message() << "r_s ±" << r_s_spread << ", δ_h " << hall_error << ", edge " << edge
                                        << ", lock bound " << lock_bound(edge));
      (hall_smaller ? hall_decided : lock_decided) = true;
      expect_rs_edge(at, c, n, edge);
      EXPECT_FALSE(at(c, -n, 0.99 * edge).bits & regime_bit::kExcitesRs);
      if (hall_smaller) {
        EXPECT_LT(edge, 0.99 * open_edge);  // the Hall bound lets r_s adapt where a sensorless frame would not
        EXPECT_FALSE(at(sensorless, n, 1.01 * edge).bits & regime_bit::kExcitesRs);
        EXPECT_FALSE(at(observer, n, 1.01 * edge).bits & regime_bit::kExcitesRs);
      } else {
        EXPECT_DOUBLE_EQ(edge, open_edge);
      }
      // Above the Hall sensors' speed: the sensorless edge. At standstill no frame error reaches the voltage: the
      // sensor's edge.
      expect_rs_edge(at, observer, n, open_edge);
      expect_rs_edge(at, c, 0.0, c.z * noise / c.r_min_pu);
    }
  }
  EXPECT_TRUE(hall_decided);
  EXPECT_TRUE(lock_decided);
}

/// Contiguous windows of `h` seconds at speed n, the current's q component given at each window's centre by
/// `iq(t)` and its mean over the window by `mean_iq(t0, t1)`, the voltage the exact window mean of the
/// machine's equations (§11: ū = M·ī + x·(i(t₁) − i(t₀))/(ω_n·h) + n·J·[ψm, 0]).
template <typename Current, typename Mean>
std::vector<Classification> windows(const RegimeConfig& c, const MachinePu& m, double omega_n, double n, double h, int count,
                                    Current iq, Mean mean_iq) {
  RegimeClassifier k(c);
  std::vector<Classification> out;
  for (int j = 0; j < count; ++j) {
    const double t0 = j * h, t1 = t0 + h;
    RegimeInput in;
    in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
    in.t_ns = std::llround(t1 * 1e9);
    in.window_s = h;
    in.i_pu = Vec2(0.0, mean_iq(t0, t1));
    in.n_pu = n;
    in.u_pu = steady_state_voltage(m, n, in.i_pu) + Vec2(0.0, m.x_q_pu * (iq(t1) - iq(t0)) / (omega_n * h));
    in.u_reported_sq_pu = in.u_pu.squaredNorm();
    out.push_back(k.step(in));
  }
  return out;
}

TEST(Regime, ARampIsTransientOnlyWhereTheInductancesToleranceOnItsCorrectionStandsOut) {
  Outrunner s;
  s.settings.regimes.current_resolution_A = 1e-6;  // the ramp's own steps are not a resolution
  const RegimeConfig c = s.config();
  // A ramp: the slope between centres is exact, so the rows' error is (Δx/ω_n)·|s| against z·σ_u.
  const double edge = c.z * (c.resolution_pu[0] / std::sqrt(12.0)) * s.base.omega_el_rad_s / c.dx_q_pu;
  auto last = [&](double slope) {
    const auto v = windows(
        c, s.nominal, s.base.omega_el_rad_s, 0.4, 0.09, 6, [=](double t) { return 0.2 + slope * t; },
        [=](double t0, double t1) { return 0.2 + slope * 0.5 * (t0 + t1); });
    return v.back();
  };
  EXPECT_FALSE(last(0.99 * edge).excluded());
  EXPECT_EQ(last(1.01 * edge).regime, Regime::kTransient);
  EXPECT_EQ(last(-1.01 * edge).regime, Regime::kTransient);
}

/// The paper's machine (L 95/206 mH) in the probes' frame, logged with 0.1 V and 10 mA resolution: its inductive
/// voltages stand far above the resolution.
Outrunner paper_machine_logged() {
  Outrunner s;
  s.machine = test::paper_machine_si();
  s.settings = test::paper_settings();
  s.base = test::paper_base();
  s.nominal = test::paper_machine_pu();
  s.settings.regimes.voltage_resolution_V = 0.1;
  s.settings.regimes.current_resolution_A = 0.01;
  return s;
}

TEST(Regime, AStepInsideAWindowMakesItAndTheNextTransient) {
  // The paper's machine (L 95/206 mH): the step's inductive voltage L·ΔI/h is far above the log's
  // resolution. (The outrunner's 20 µH makes it 6 mV for 28 A in 90 ms, below VESC Tool's 10 mV: there
  // the speed-current covariance of an acceleration is what shows, RegimeEstimators.*.)
  const Outrunner s = paper_machine_logged();
  const RegimeConfig c = s.config();
  const double h = 0.09, step_at = 5 * h + 0.3 * h;  // in window 5, 30 % into it
  const double i0 = 0.1, i1 = 0.6;
  const auto iq = [=](double t) { return t < step_at ? i0 : i1; };
  const auto mean = [=](double t0, double t1) {
    const double a = std::clamp(step_at, t0, t1);
    return (i0 * (a - t0) + i1 * (t1 - a)) / (t1 - t0);
  };
  const auto v = windows(c, s.nominal, s.base.omega_el_rad_s, 0.4, h, 12, iq, mean);
  for (int j = 1; j < 5; ++j) EXPECT_FALSE(v[j].excluded()) << j;
  // The windows whose correction the step falsifies (5: it holds the step; 6: its slope straddles it).
  EXPECT_EQ(v[5].regime, Regime::kTransient);
  EXPECT_EQ(v[6].regime, Regime::kTransient);
  for (int j = 9; j < 12; ++j) EXPECT_FALSE(v[j].excluded()) << j;
}

// §13, "… where the acceleration changes": a window whose speed is off by up to E (a PLL's reads rebuilt to the
// window's mean) is transient where E·(x_q·|i_q|, x_d·|i_d| + ψ_max) stands out of z times the row's noise together with
// the speed's own through the same coefficients. The current holds (a stop at constant current), so no other test
// sees it; a speed whose noise covers E (reads that jitter) leaves the window as it was.
TEST(Regime, ASpeedKnownWithinItsRebuildsErrorIsTransientWhereItStandsOutOfTheSpeedsNoise) {
  Outrunner s;
  s.settings.regimes.current_resolution_A = 0.01;
  s.settings.regimes.speed_resolution_rad_s = 0.10472;  // 1 erpm
  const double n = 0.4, h = 0.09;
  const Vec2 i(-0.05, 0.2);
  // Steady contiguous windows, exact (their noise is the resolutions' quantisation); the last one's speed off by E.
  const auto last = [&](const RegimeConfig& c, double error_pu, double error_noise_pu = 0.0) {
    RegimeClassifier k(c);
    Classification out;
    for (int j = 0; j < 8; ++j) {
      RegimeInput in = steady(s.nominal, n, i);
      in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
      in.t_ns = std::llround((j + 1) * h * 1e9);
      in.window_s = h;
      in.n_error_pu = j == 7 ? error_pu : 0.0;
      in.n_error_noise_pu = j == 7 ? error_noise_pu : 0.0;
      out = k.step(in);
    }
    return out;
  };
  // The edge written out: the smaller of the rows' E at which E²·coeff² = z²·(row + coeff²·σ_n²).
  const auto edge = [&](const RegimeConfig& c) {
    const auto var = [&](std::size_t q) { return c.resolution_pu[q] * c.resolution_pu[q] / 12.0; };
    const double coeff_d = c.x_q_pu * std::abs(i[1]), coeff_q = c.x_d_pu * std::abs(i[0]) + c.psi_max_pu;
    const double row_d = var(0) + (c.r_pu * c.r_pu + n * n * c.x_q_pu * c.x_q_pu) * var(1);
    const double row_q = var(0) + (c.r_pu * c.r_pu + n * n * c.x_d_pu * c.x_d_pu) * var(1);
    return std::min(c.z * std::sqrt(row_d / (coeff_d * coeff_d) + var(2)),
                    c.z * std::sqrt(row_q / (coeff_q * coeff_q) + var(2)));
  };
  const RegimeConfig c = s.config();
  const double e = edge(c);
  EXPECT_FALSE(last(c, 0.0).excluded());
  EXPECT_FALSE(last(c, 0.99 * e).excluded());
  EXPECT_EQ(last(c, 1.01 * e).regime, Regime::kTransient);
  EXPECT_TRUE(last(c, 1.01 * e).bits & regime_bit::kExcitesPsiM);  // excited, and excluded all the same
  // Its size: a few rad/s (1.6 here) against the 101 rad/s of seed 1's stop (docs/derivations.md).
  EXPECT_LT(e * s.base.omega_el_rad_s, 5.0);
  // Speed readings in steps 100 times as coarse: the same E lies within their noise.
  s.settings.regimes.speed_resolution_rad_s = 100.0 * 0.10472;
  const RegimeConfig jittery = s.config();
  EXPECT_GT(edge(jittery), 5.0 * e);
  EXPECT_FALSE(last(jittery, 1.01 * e).excluded());
  EXPECT_EQ(last(jittery, 1.01 * edge(jittery)).regime, Regime::kTransient);
  // E's own noise (the reads' changes of acceleration around the window) adds to the speed's: an E of 3 times its
  // noise σ_E, with z = 4, is within it; the edge moves to z·√(edge²/z² + σ_E²).
  const double sigma_e = 10.0 * e;
  EXPECT_FALSE(last(c, 3.0 * sigma_e, sigma_e).excluded());
  const double moved = c.z * std::sqrt(e * e / (c.z * c.z) + sigma_e * sigma_e);
  EXPECT_FALSE(last(c, 0.99 * moved, sigma_e).excluded());
  EXPECT_EQ(last(c, 1.01 * moved, sigma_e).regime, Regime::kTransient);
}

/// Windows of h at speed n over a timeline: the bridge modulates (current i_mod, the machine's steady-state
/// voltage) until t_release, is off (a drive that reports zeros while off: u = i = 0) until t_take_over and
/// modulates again afterwards. Each window's means are its parts' time-weighted means; `share` the part of
/// each window in which the bridge modulated, as the timeline gives it.
struct BridgeTimeline {
  double h = 0.09, n = 0.4, t_release = 0.0, t_take_over = 0.0;
  Vec2 i_mod = Vec2(0.0, 0.1);
  [[nodiscard]] double share(int j) const {
    const double t0 = j * h, t1 = t0 + h;
    const double off = std::max(0.0, std::min(t1, t_take_over) - std::max(t0, t_release)) / h;
    return off > 1.0 - 1e-9 ? 0.0 : 1.0 - off;  // a whole window off (its ends' rounding aside)
  }
  [[nodiscard]] std::vector<Classification> classify(const RegimeConfig& c, const MachinePu& m, int count,
                                                     RegimeCounts* counts = nullptr) const {
    RegimeClassifier k(c);
    std::vector<Classification> out;
    const Vec2 u_mod = steady_state_voltage(m, n, i_mod);
    for (int j = 0; j < count; ++j) {
      RegimeInput in;
      in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
      in.t_ns = std::llround((j + 1) * h * 1e9);
      in.window_s = h;
      in.n_pu = n;
      in.u_pu = share(j) * u_mod;
      in.i_pu = share(j) * i_mod;
      in.u_reported_sq_pu = in.u_pu.squaredNorm();
      out.push_back(k.step(in));
      if (counts) counts->add(out.back());
    }
    return out;
  }
};

TEST(Regime, AWindowHoldingTheBridgesReleaseOrTakeOverIsMixed) {
  // §13, "Mixed windows": the window between the last modulating and the first bridge-off window holds the
  // release, the one after the last bridge-off window the take-over. With zeros reported while off its means
  // are share·(modulating means): the model reads ψm·share — inside D_M (±50 %) for shares above ½, so
  // nothing in the window itself tells it apart; the outrunner's 20 µH keep the current's change below
  // the transient test's threshold (x·Δi/(ω_n·h) ≈ 1e-5 pu against z·σ_u ≈ 3e-4 pu).
  Outrunner s;
  s.settings.regimes.current_resolution_A = 0.01;
  const RegimeConfig c = s.config();
  for (const double f : {0.1, 0.5, 0.9}) {  // where in its window each change falls
    BridgeTimeline b;
    b.t_release = (6.0 + f) * b.h;
    b.t_take_over = (11.0 + f) * b.h;
    RegimeCounts counts;
    const std::vector<Classification> v = b.classify(c, s.nominal, 16, &counts);
    // Expected from the timeline alone: off where the bridge never modulated, mixed where it changed.
    for (int j = 1; j < 16; ++j) {
      const double m = b.share(j);
      const bool mixed = m > 0.0 && m < 1.0, off = m == 0.0;
      if (off) {
        EXPECT_EQ(v[j].regime, Regime::kBridgeOff) << f << " " << j;
      } else if (mixed && j == 6) {
        // The release: its own evidence admits it, the next window (the first off one) marks it mixed.
        EXPECT_FALSE(v[j].excluded()) << f;
        EXPECT_TRUE(v[j + 1].bits & regime_bit::kPreviousMixed) << f;
      } else if (mixed) {
        EXPECT_EQ(v[j].regime, Regime::kTransient) << f << " " << j;  // the take-over, causally
      } else {
        EXPECT_FALSE(v[j].excluded()) << f << " " << j;
        EXPECT_FALSE(v[j].bits & regime_bit::kPreviousMixed) << f << " " << j;
      }
    }
    EXPECT_EQ(counts[Regime::kBridgeOff], 4U) << f;  // windows 7–10
    EXPECT_EQ(counts[Regime::kTransient], 2U) << f;  // 6 (moved by 7's mark) and 11
    EXPECT_EQ(counts.total(), 16U) << f;
  }
  // A change exactly at a read leaves no window mixed, but nothing in the data says so: the window beside
  // the off ones is set aside all the same (one window's data per change, the rule's price).
  BridgeTimeline b;
  b.t_release = 6.0 * b.h;
  b.t_take_over = 11.0 * b.h;
  const std::vector<Classification> v = b.classify(c, s.nominal, 16);
  EXPECT_EQ(v[5].regime, Regime::kExcitesPsiM);
  EXPECT_TRUE(v[6].bits & regime_bit::kPreviousMixed);
  EXPECT_EQ(v[10].regime, Regime::kBridgeOff);
  EXPECT_EQ(v[11].regime, Regime::kTransient);
  EXPECT_FALSE(v[12].excluded());
  // A drive that reports the back EMF while off (VESC's firmware) shows no bridge-off window: its mixed
  // windows are the model's own (u = n·ψm at i = 0 while off), and nothing is set aside.
}

/// Contiguous 90 ms windows at speed n with white noise of σ (pu) on u and i: window `mixed_at` holds `inside(u, i)`,
/// what the bridge did inside it; a steady operating point elsewhere. The classifications, and the noise the window
/// after `mixed_at` judged it against (RegimeState::flux_noise, read before that window enters).
struct NoisyWindows {
  double h = 0.09, n = 0.4, sigma = 1e-3;
  Vec2 i = Vec2::Zero();
  int count = 60, mixed_at = 40;
  std::uint64_t seed = 1;
  template <typename Inside>
  std::vector<Classification> classify(const RegimeConfig& c, const MachinePu& m, Inside inside,
                                       RegimeNoise* judged_with = nullptr) const {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    RegimeClassifier k(c);
    std::vector<Classification> out;
    const Vec2 u = steady_state_voltage(m, n, i);
    for (int j = 0; j < count; ++j) {
      Vec2 uj = u, ij = i;
      if (j == mixed_at) inside(uj, ij);
      RegimeInput in = chain_sample(j, std::llround((j + 1) * h * 1e9), uj + Vec2(noise(rng), noise(rng)),
                                    ij + Vec2(noise(rng), noise(rng)), n);
      in.window_s = h;
      out.push_back(k.step(in));
      if (j == mixed_at && judged_with) *judged_with = k.state().flux_noise;
    }
    return out;
  }
};

TEST(Regime, AWindowWhoseFluxLeavesBothNeighboursHeldAFreewheel) {
  // §13, "… inside one window": the bridge released and taken over inside one window, zeros reported while off, its
  // means m times the modulating ones. At zero current (coasting, the bridge modulating) the flux reads m·ψ and no
  // lever of the tolerance moves: the edge is (1 − m)·ψ = z·√(2·σ_ψ²), σ_ψ² = (σ_u² + (r² + 3·a·(r + a) + n²·x_d²)·σ_i²
  // + ψ_max²·σ_n²)/n², a = x_q/(ω_n·h), recomputed here from the noise the judging window used. Checked at twice the edge (flagged,
  // by the window after it: kPreviousMixed) and at a quarter of it (not), over seeds.
  Outrunner s;
  s.settings.regimes.voltage_resolution_V = 0.0;  // the noise, measured
  const RegimeConfig c = s.config();
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    NoisyWindows w;
    w.seed = test::test_seed(seed);
    RegimeNoise v;
    (void)w.classify(
        c, s.nominal, [](Vec2&, Vec2&) {}, &v);
    const double inv_dt = 1.0 / w.h, n2 = w.n * w.n;
    const double a = c.x_q_pu * inv_dt / c.omega_n_rad_s;
    const double per_i = c.r_pu * c.r_pu + 3.0 * a * (c.r_pu + a) + n2 * c.x_d_pu * c.x_d_pu;
    const double var = (v.u_sq + per_i * v.i_sq + c.psi_max_pu * c.psi_max_pu * v.n_sq) / n2;
    const double edge = c.z * std::sqrt(2.0 * var) / s.nominal.psi_m_pu;  // 1 − m at the edge
    ASSERT_GT(edge, 0.0);
    ASSERT_LT(edge, 0.2);
    for (const double factor : {2.0, 0.25}) {
      const double m = 1.0 - factor * edge;
      const auto v2 = w.classify(c, s.nominal, [m](Vec2& u, Vec2& i) {
        u *= m;
        i *= m;
      });
      EXPECT_FALSE(v2[40].excluded()) << w.seed;  // nothing in the window alone tells it
      EXPECT_EQ((v2[41].bits & regime_bit::kPreviousMixed) != 0, factor > 1.0) << w.seed << " m " << m;
      for (int j = 1; j < 60; ++j) {
        if (j != 41) {
          EXPECT_FALSE(v2[j].bits & regime_bit::kPreviousMixed) << w.seed << " " << j;
        }
      }
    }
  }
  // Under load the levers move with the mix: a half-window freewheel at 0.1 pu of q current is found all the same, and
  // counted as transient once the next window has judged it.
  NoisyWindows w;
  w.i = Vec2(0.0, 0.1);
  RegimeCounts counts;
  const auto v = w.classify(c, s.nominal, [](Vec2& u, Vec2& i) {
    u *= 0.5;
    i *= 0.5;
  });
  for (const Classification& r : v) counts.add(r);
  EXPECT_TRUE(v[41].bits & regime_bit::kPreviousMixed);
  EXPECT_EQ(counts[Regime::kTransient], 1U);
}

TEST(Regime, AWindowMixingTwoOperatingPointsOfAMachineWithinTheToleranceStaysBetweenItsNeighbours) {
  // A load changed inside a window (a step, or a pulse that ends inside it) mixes two steady states: at the window's
  // speed the flux the nominal model reads is linear in u and i, so the mix lies between its neighbours' but for what
  // Δr, Δx_d do over the operating points' difference — the tolerance the test allows. Seeded machines with r_s in
  // D_M and x_d within 90 % of the tolerance, and little noise, so that the tolerance alone decides: nothing is mixed.
  Outrunner s;
  s.settings.regimes.voltage_resolution_V = 0.0;
  s.settings.regimes.current_resolution_A = 0.0;
  const RegimeConfig c = s.config();
  const std::uint64_t seed = test::test_seed(2302);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int flagged = 0, judged = 0;
  for (int run = 0; run < 100; ++run) {
    MachinePu plant = s.nominal;
    plant.r_s_pu = std::max(0.5 * c.r_min_pu, c.r_pu + 0.9 * c.dr_pu * (2.0 * unit(rng) - 1.0));  // |Δr| within D_M's
    plant.x_d_pu = s.nominal.x_d_pu * (1.0 + 0.9 * 0.3 * (2.0 * unit(rng) - 1.0));
    const double n = 0.2 + 0.8 * unit(rng);
    const Vec2 a(-0.5 * unit(rng), 2.0 * unit(rng) - 1.0), b(-0.5 * unit(rng), 2.0 * unit(rng) - 1.0);
    const double share = unit(rng);
    const bool pulse = run % 2 == 1;
    std::normal_distribution<double> noise(0.0, 1e-6);
    RegimeClassifier k(c);
    for (int j = 0; j < 40; ++j) {
      const Vec2 i = j < 20 ? a : (j == 20 || pulse ? a : b);
      const Vec2 i_mix = share * a + (1.0 - share) * b;
      const Vec2 ij = j == 20 ? i_mix : i;
      const Vec2 uj = j == 20 ? share * steady_state_voltage(plant, n, a) + (1.0 - share) * steady_state_voltage(plant, n, b)
                              : steady_state_voltage(plant, n, i);
      RegimeInput in =
          chain_sample(j, (j + 1) * 90'000'000LL, uj + Vec2(noise(rng), noise(rng)), ij + Vec2(noise(rng), noise(rng)), n);
      in.window_s = 0.09;
      const Classification r = k.step(in);
      if (j == 21) {
        ++judged;
        flagged += (r.bits & regime_bit::kPreviousMixed) ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(flagged, 0) << "seed " << seed << " of " << judged;

  // A step inside a window with its inductive voltage (the paper's machine, L 95/206 mH): the correction between
  // window centres misses part of it in the window holding the step and in the next, at most (x_q + Δx_q)/ω_n times
  // their slopes, the reach the test allows; beyond that the slope change is the transient test's. Anywhere inside the
  // window, at any height from below the noise to far above it: nothing is marked.
  const Outrunner p = paper_machine_logged();
  const RegimeConfig pc = p.config();
  const double h = 0.09;
  for (int f = 1; f < 20; ++f) {
    for (double height = 1e-4; height < 2.0; height *= 1.5) {
      const double step_at = (5.0 + 0.05 * f) * h;
      const auto iq = [=](double t) { return t < step_at ? 0.1 : 0.1 + height; };
      const auto mean = [=](double t0, double t1) {
        const double a = std::clamp(step_at, t0, t1);
        return (0.1 * (a - t0) + (0.1 + height) * (t1 - a)) / (t1 - t0);
      };
      const auto v = windows(pc, p.nominal, p.base.omega_el_rad_s, 0.4, h, 12, iq, mean);
      for (int j = 0; j < 12; ++j) {
        EXPECT_FALSE(v[j].bits & regime_bit::kPreviousMixed) << f << " " << height << " " << j;
      }
    }
  }
}

TEST(Regime, AStandaloneSampleIsSteadyOnceTheTransientHasDecayedIntoTheNoise) {
  Outrunner s;
  s.settings.regimes.current_resolution_A = 0.05;
  const RegimeConfig c = s.config();
  // The remnant of the change from the previous sample, e^{−Δt/τ}·|Δi|, against z·σ_i·√(1 + 2·e^{−2Δt/τ}),
  // τ = max(x)/(ω_n·r_min); the boundary by bisection.
  const double tau = std::max(s.nominal.x_d_pu, s.nominal.x_q_pu) / (s.base.omega_el_rad_s * c.r_min_pu);
  EXPECT_NEAR(tau, 20e-6 / 0.0125, 1e-12);
  const double sigma = c.resolution_pu[1] / std::sqrt(12.0), change = 0.5;
  auto excess = [&](double dt) {
    const double d = std::exp(-dt / tau);
    return d * change - c.z * sigma * std::sqrt(1.0 + 2.0 * d * d);
  };
  double lo = 0.0, hi = 100.0 * tau;
  for (int k = 0; k < 200; ++k) (excess(0.5 * (lo + hi)) > 0.0 ? lo : hi) = 0.5 * (lo + hi);
  const double edge = 0.5 * (lo + hi);
  auto after = [&](double dt) {
    RegimeClassifier k(c);
    RegimeInput in = steady(s.nominal, 0.3, Vec2(0.0, 0.1));
    for (int j = 0; j < 3; ++j) {
      in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
      in.t_ns = (j + 1) * 1'000'000LL;
      (void)k.step(in);
    }
    RegimeInput next = steady(s.nominal, 0.3, Vec2(0.0, 0.1 + change));
    next.timing = SampleTiming::kStandalone;
    next.t_ns = in.t_ns + std::llround(dt * 1e9);
    return k.step(next);
  };
  EXPECT_EQ(after(0.99 * edge).regime, Regime::kTransient);
  EXPECT_FALSE(after(1.01 * edge).excluded());
  EXPECT_GT(edge, 3.0 * tau);
}

TEST(Regime, NoiseAndResolutionAreMeasuredFromTheData) {
  Outrunner s;
  s.settings.regimes.voltage_resolution_V = 0.0;  // measured
  const RegimeConfig c = s.config();
  const std::uint64_t seed = test::test_seed(23);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> spacing(0.5, 1.5);
  // Ramps at uneven spacing with white noise of known σ: the normalised second difference removes both.
  const double su = 2e-3, si = 5e-3, sn = 1e-3;
  std::normal_distribution<double> nu(0.0, su), ni(0.0, si), nn(0.0, sn);
  RegimeClassifier k(c);
  double t = 0.0, mean_u = 0.0, mean_i = 0.0, mean_n = 0.0;
  int counted = 0;
  for (int j = 0; j < 40000; ++j) {
    t += 0.01 * spacing(rng);
    const Vec2 u(0.1 + 0.2 * t + nu(rng), 0.5 - 0.1 * t + nu(rng));
    const Vec2 i(-0.1 + ni(rng), 0.3 + 0.05 * t + ni(rng));
    (void)k.step(chain_sample(j, std::llround(t * 1e9), u, i, 0.5 + 0.01 * t + nn(rng)));
    if (j >= 2000) {
      const RegimeNoise v = k.current_noise();
      mean_u += std::sqrt(v.u_sq), mean_i += std::sqrt(v.i_sq), mean_n += std::sqrt(v.n_sq);
      ++counted;
    }
  }
  std::printf("noise ratios %.4f %.4f %.4f\n", mean_u / counted / su, mean_i / counted / si, mean_n / counted / sn);
  EXPECT_NEAR(mean_u / counted / su, 1.0, 0.05) << "seed " << seed;
  EXPECT_NEAR(mean_i / counted / si, 1.0, 0.05) << "seed " << seed;
  EXPECT_NEAR(mean_n / counted / sn, 1.0, 0.05) << "seed " << seed;

  // Quantised and quiet (noise far below the quantum): the resolution is the quantum, σ² = q²/12.
  RegimeClassifier q(c);
  const double quantum = 1e-3;
  for (int j = 0; j < 500; ++j) {
    const double raw = 0.4 + 0.00037 * j + 1e-6 * nu(rng);
    const Vec2 u(quantum * std::round(raw / quantum), quantum * std::round(0.5 * raw / quantum));
    (void)q.step(chain_sample(j, (j + 1) * 10'000'000LL, u, Vec2(0.0, 0.2), 0.4));
  }
  EXPECT_NEAR(q.state().measured_resolution_pu[0] / quantum, 1.0, 1e-9);
  EXPECT_GE(q.current_noise().u_sq, quantum * quantum / 12.0);
  EXPECT_LT(q.current_noise().u_sq, 2.0 * quantum * quantum / 12.0 + 4.0 * quantum * quantum);
}

/// P(X_(j) ≤ x) for the j-th smallest of n |N(0, 1)| (1-based): at least j of n fall below x, each with
/// probability erf(x/√2).
double order_statistic_cdf(int j, int n, double x) {
  const double f = std::erf(x / std::sqrt(2.0));
  double p = 0.0;
  for (int k = j; k <= n; ++k)
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0)) * std::pow(f, k) *
         std::pow(1.0 - f, n - k);
  return p;
}
/// Its quantile by bisection.
double order_statistic_quantile(int j, int n, double p) {
  double lo = 0.0, hi = 10.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (order_statistic_cdf(j, n, mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Regime, ANoiseMedianStartedByATransientIsTheNoisesAfterItsWarmUp) {
  // A chain that begins with an operating-point change — a step between its 2nd and 3rd samples, or a
  // run-up's two corners (its 2nd and 6th) — then white noise of known σ per quantity. The step puts 2
  // residuals per lane far above the noise (the two triples that straddle it), the run-up 1 per corner: o = 4
  // of u's and i's residuals (two lanes), 2 of n's. The median of c residuals (the lower middle one of an even
  // count, 1-based j = ⌊(c − 1)/2⌋ + 1) is then the j-th smallest of the c − o noise residuals |N(0, σ²)|, whose
  // distribution is exact (order_statistic_cdf): asserted inside its quantiles 1e-7 and 1 − 1e-7 in every
  // trial, and its median between the trials' 36th and 64th percentile (a binomial's ±4σ over 200 trials).
  // Checked after 10 samples for u and i (c = 16), 17 for n (c = 15): within K = 17 samples.
  // The tracker as it was (started by the first nonzero residual, then e^{±1/16} a residual) is at least
  // r₁·e^{−(c−1)/16} there, r₁ = 0.8165·S/2 the step's first residual (d's lane: half the step): 237× the
  // noise's median on u and i, 252× on n (asserted beyond 50× the new start's 1 − 1e-7 quantile), which is
  // what the classifier's thresholds were made of before (cd50b73).
  Outrunner s;
  s.settings.regimes.voltage_resolution_V = 0.0;
  const RegimeConfig c = s.config();
  const std::uint64_t seed = test::test_seed(2317);
  std::mt19937_64 rng(seed);
  const std::array<double, 3> sigma{1e-4, 2e-4, 1e-4};  // u, i, n
  const std::array<double, 3> step{0.2, 0.4, 0.1};
  constexpr double kMedianOverSigma = 0.6744897501960817;  // Φ⁻¹(3/4)
  constexpr double kEta = 1.0 / 16.0;
  const std::array<int, 3> taken{16, 16, 15}, outliers{4, 4, 2}, check_after{10, 10, 17};
  for (const bool run_up : {false, true}) {
    std::array<std::vector<double>, 3> ratio;  // learnt median / the noise's
    for (int trial = 0; trial < 200; ++trial) {
      std::normal_distribution<double> unit(0.0, 1.0);
      RegimeClassifier k(c);
      for (int j = 0; j < 17; ++j) {
        // The operating point's change: a step from sample 2 on, or a ramp over samples 1–5.
        const double level = run_up ? std::clamp((j - 1) / 4.0, 0.0, 1.0) : (j >= 2 ? 1.0 : 0.0);
        const Vec2 u(0.05 + 0.5 * step[0] * level + sigma[0] * unit(rng), 0.3 + step[0] * level + sigma[0] * unit(rng));
        const Vec2 i(-0.05 - 0.5 * step[1] * level + sigma[1] * unit(rng), 0.1 + step[1] * level + sigma[1] * unit(rng));
        (void)k.step(chain_sample(j, (j + 1) * 10'000'000LL, u, i, 0.3 + step[2] * level + sigma[2] * unit(rng)));
        for (std::size_t q = 0; q < 3; ++q)
          if (j + 1 == check_after[q]) ratio[q].push_back(k.state().noise_median_pu[q] / (kMedianOverSigma * sigma[q]));
      }
    }
    for (std::size_t q = 0; q < 3; ++q) {
      const int order = (taken[q] - 1) / 2 + 1, noise = taken[q] - outliers[q];
      const double lo = order_statistic_quantile(order, noise, 1e-7) / kMedianOverSigma;
      const double hi = order_statistic_quantile(order, noise, 1.0 - 1e-7) / kMedianOverSigma;
      const double mid = order_statistic_quantile(order, noise, 0.5) / kMedianOverSigma;
      const auto [min, max] = std::minmax_element(ratio[q].begin(), ratio[q].end());
      const auto below = std::count_if(ratio[q].begin(), ratio[q].end(), [&](double r) { return r < mid; });
      std::printf("%s q%zu: learnt/true median %.3f..%.3f (band %.3f..%.3f), %ld of 200 below %.3f\n",
                  run_up ? "run-up" : "step", q, *min, *max, lo, hi, static_cast<long>(below), mid);
      EXPECT_GE(*min, lo) << "quantity " << q << ", seed " << seed;
      EXPECT_LE(*max, hi) << "quantity " << q << ", seed " << seed;
      EXPECT_GE(below, 72) << "quantity " << q << ", seed " << seed;
      EXPECT_LE(below, 128) << "quantity " << q << ", seed " << seed;
      if (!run_up) {
        const double first = 0.81649658 * 0.5 * step[q] * (q == 2 ? 1.0 : 0.5);  // the smaller lane's step
        const double old_bound = first * std::exp(-kEta * (taken[q] - 1)) / (kMedianOverSigma * sigma[q]);
        EXPECT_GT(old_bound, 50.0 * hi) << "quantity " << q;  // beyond the new start's every plausible value
      }
    }
  }
}

TEST(Regime, AfterItsWarmUpTheNoiseMedianStepsAsTheTrackerAlways) {
  // Steady white noise on n alone (one residual per sample, computed here as the classifier forms it at even
  // spacing, w = ½): once warmed up (17 residuals) the median moves by exactly e^{±1/16} per residual, up
  // where |r| > m — the tracker of §13 unchanged, so its stationary statistics are the old ones. §13 derives
  // them for independent residuals: log m about log(0.6745·σ) with spread √(η/(4f)) = 0.19, m's mean +1.9 %.
  // Neighbouring residuals share samples (consecutive r correlate −2/3 at even spacing), so consecutive |r|
  // fall on the same side of m more often than independent ones and the walk's spread is wider: measured
  // 0.23 here; m's mean +1.9 to +2.7 % over seeds. Asserted: every step exact; the mean +1.9 % ± 1.5 %; the spread from the
  // independent residuals' 0.19 to 0.27 (the sampling error over 200 000 residuals, correlated over
  // 1/(2ηf) ≈ 19 steps, is 0.002 in log m).
  Outrunner s;
  s.settings.regimes.speed_resolution_rad_s = 1e-12;
  const RegimeConfig c = s.config();
  const std::uint64_t seed = test::test_seed(2318);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1e-3);
  RegimeClassifier k(c);
  std::array<double, 3> n{};
  double sum_log = 0.0, sum_log_sq = 0.0, sum_m = 0.0;
  int steps = 0, exact = 0;
  const double up = std::exp(1.0 / 16.0), down = std::exp(-1.0 / 16.0);
  for (int j = 0; j < 200'000; ++j) {
    const RegimeInput in = chain_sample(j, (j + 1) * 10'000'000LL, Vec2(0.05, 0.3), Vec2(-0.05, 0.1), 0.3 + noise(rng));
    const double before = k.state().noise_median_pu[2];
    (void)k.step(in);
    n = {n[1], n[2], in.n_pu};
    if (j < 2 + 17) continue;  // the warm-up: the first residual comes with the third sample
    const double r = 0.81649658 * std::abs(n[1] - (0.5 * n[2] + 0.5 * n[0]));
    const double m = k.state().noise_median_pu[2];
    exact += std::abs(m / before - (r > before ? up : down)) < 1e-15;
    const double l = std::log(m / (0.6744897501960817 * 1e-3));
    sum_log += l;
    sum_m += std::exp(l);
    sum_log_sq += l * l;
    ++steps;
  }
  const double mean = sum_log / steps, spread = std::sqrt(sum_log_sq / steps - mean * mean);
  const double mean_m = sum_m / steps;
  std::printf(
      "tracker: %d of %d steps e^{±1/16} in |r|'s direction; log m − log median: mean %.4f, spread %.4f; "
      "m / median %.4f\n",
      exact, steps, mean, spread, mean_m);
  EXPECT_GE(exact, steps - 2) << "seed " << seed;  // |r| within an ulp of m can go either way
  EXPECT_NEAR(mean_m, 1.019, 0.015) << "seed " << seed;
  EXPECT_GE(spread, 0.19 - 0.01) << "seed " << seed;
  EXPECT_LE(spread, 0.27) << "seed " << seed;
}

TEST(Regime, LockedSteadyNoisyDataIsExcludedNoMoreOftenThanTheFalseRate) {
  // Seeded machines inside the configuration's uncertainty (r_s in D_M, ψm in D_M, x within its
  // tolerance), locked, at random steady operating points, with white noise on u, i and n: every exclusion
  // is a false one. Each of the rows' tests fires with two-sided rate α = erfc(z/√2) on a known σ; the
  // median tracker's spread (§13) and the rows' several tests allow a few α — checked here at 4·α per sample.
  Outrunner s;
  s.settings.regimes.voltage_resolution_V = 0.0;
  const RegimeConfig c = s.config();
  const std::uint64_t seed = test::test_seed(2301);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  long judged = 0, excluded = 0, mixed = 0;
  for (int run = 0; run < 200; ++run) {
    MachinePu plant = s.nominal;
    plant.r_s_pu = c.r_min_pu + (2.0 * c.dr_pu) * unit(rng) * 0.7;
    plant.psi_m_pu = c.psi_min_pu + (c.psi_max_pu - c.psi_min_pu) * unit(rng);
    plant.x_d_pu = s.nominal.x_d_pu * (1.0 + 0.3 * (2.0 * unit(rng) - 1.0));
    plant.x_q_pu = s.nominal.x_q_pu * (1.0 + 0.3 * (2.0 * unit(rng) - 1.0));
    const double n = 2.0 * unit(rng) - 1.0;
    const Vec2 i(-0.3 * unit(rng), 2.0 * unit(rng) - 1.0);
    const double sigma = std::pow(10.0, -4.0 + 2.0 * unit(rng));
    std::normal_distribution<double> noise(0.0, sigma);
    RegimeClassifier k(c);
    const RegimeInput clean = steady(plant, n, i);
    for (int j = 0; j < 400; ++j) {
      RegimeInput in = clean;
      in.timing = j == 0 ? SampleTiming::kFirst : SampleTiming::kContiguous;
      in.t_ns = (j + 1) * 50'000'000LL;
      in.window_s = 0.05;
      in.u_pu += Vec2(noise(rng), noise(rng));
      in.i_pu += Vec2(noise(rng), noise(rng)) * 0.3;
      in.n_pu += noise(rng) * 0.1;
      in.u_reported_sq_pu = in.u_pu.squaredNorm();
      const Classification r = k.step(in);
      if (j < 50) continue;  // the noise tracker settling
      ++judged;
      excluded += r.excluded() ? 1 : 0;
      mixed += (r.bits & regime_bit::kPreviousMixed) ? 1 : 0;  // the window before found mixed: as false
    }
  }
  const double alpha = std::erfc(c.z / std::sqrt(2.0));
  EXPECT_LE(static_cast<double>(excluded), 4.0 * alpha * static_cast<double>(judged) + 3.0)
      << "seed " << seed << ": " << excluded << " of " << judged;
  // Both of a window's differences beyond z·σ on one side: no likelier than one of them (α, two-sided).
  EXPECT_LE(static_cast<double>(mixed), 4.0 * alpha * static_cast<double>(judged) + 3.0)
      << "seed " << seed << ": " << mixed << " of " << judged;
}

}  // namespace
}  // namespace rpem::core
