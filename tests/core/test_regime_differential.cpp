// core::RegimeClassifier against its previous formulation (tests/core/regime_reference.hpp), bit for bit:
// its cost was cut (issue 23 item 7: pairs of trackers in one SSE2 lane pair, shared subexpressions), and
// none of that may move a decision. Streams of every timing and regime — smooth operating points with noise,
// bridge off, frames turned off the rotor's, steps, standalone samples, repeated and reversed times, non-finite
// and overflowing values, broken chains and resets — through both; every output the consumers read is
// compared exactly: the bits, the noise the sample was judged against, the slope, the learnt state.
// The noise medians' start changed on purpose since (branch noisestart, §13 "Start (warm-up)"): the
// reference states the new start in its own form (selection on the residuals as they came, where production
// inserts into a sorted buffer), so the comparison stays whole; resets now and then repeat the warm-up.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "core/regime_reference.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/core/regime.hpp"
#include "rpem/core/settings.hpp"
#include "support/outrunner_machine.hpp"
#include "support/paper_machine.hpp"
#include "support/seed.hpp"

namespace rpem::core {
namespace {

/// Bit patterns equal (NaN against NaN too, +0 against −0 not): "the same number" for a differential test.
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same(const Vec2& a, const Vec2& b) { return same(a[0], b[0]) && same(a[1], b[1]); }

/// A stream that visits every regime: an operating point drifting with noise, and now and then something
/// else — the bridge released, the frame turned, a step, a far sample, a degenerate or non-finite value.
class Stream {
 public:
  explicit Stream(std::uint64_t seed) : rng_(seed), speed_error_rng_(~seed) {}

  RegimeInput next() {
    RegimeInput in;
    const double r = uniform(0.0, 1.0);
    // The operating point drifts; now and then it jumps.
    if (r < 0.02) {
      n_ = uniform(-1.2, 1.2);
      i_ = Vec2(uniform(-1.0, 0.3), uniform(-1.5, 1.5));
    }
    n_ += gauss(1e-3);
    i_ += Vec2(gauss(2e-3), gauss(2e-3));
    const double noise = std::pow(10.0, uniform(-7.0, -2.0)) * (r < 0.9 ? 1.0 : 0.0);
    // u of a machine near the configured one: r·i + n·(x_d·i_d + ψ, … ) — the rotor frame's steady state.
    Vec2 u(0.02 * i_[0] - n_ * 0.6 * i_[1], 0.02 * i_[1] + n_ * (0.5 * i_[0] + 0.9));
    in.u_pu = u + Vec2(gauss(noise), gauss(noise));
    in.i_pu = i_ + Vec2(gauss(noise), gauss(noise));
    in.n_pu = n_ + gauss(noise);
    const double mode = uniform(0.0, 1.0);
    if (mode < 0.05) {  // bridge off: nothing modulates, nothing flows
      in.u_pu = Vec2(gauss(noise), gauss(noise));
      in.i_pu = Vec2(gauss(noise), gauss(noise));
    } else if (mode < 0.08) {  // the frame turned off the rotor's
      const double a = uniform(-3.2, 3.2), c = std::cos(a), s = std::sin(a);
      in.u_pu = Vec2(c * in.u_pu[0] - s * in.u_pu[1], s * in.u_pu[0] + c * in.u_pu[1]);
    } else if (mode < 0.10) {  // a quantised value: the same as the last one
      in.u_pu = last_u_;
      in.i_pu = last_i_;
      in.n_pu = last_n_;
    } else if (mode < 0.11) {  // zeros, signed
      in.u_pu = Vec2(0.0, -0.0);
      in.i_pu = Vec2(-0.0, 0.0);
      in.n_pu = uniform(0.0, 1.0) < 0.5 ? 0.0 : -0.0;
    } else if (mode < 0.13) {  // the bridge off for part of the window, zeros reported: the means scaled
      const double share = uniform(0.2, 0.95);
      in.u_pu *= share;
      in.i_pu *= share;
    }
    last_u_ = in.u_pu;
    last_i_ = in.i_pu;
    last_n_ = in.n_pu;

    // Timing: mostly contiguous windows; dense blocks, first samples, standalone rows; times that repeat,
    // go back, or jump far.
    const double tr = uniform(0.0, 1.0);
    in.timing = tr < 0.70   ? SampleTiming::kContiguous
                : tr < 0.85 ? SampleTiming::kDense
                : tr < 0.92 ? SampleTiming::kStandalone
                            : SampleTiming::kFirst;
    const double step_s = uniform(0.0, 1.0) < 0.02   ? uniform(-0.01, 0.0)  // back in time, or repeated
                          : uniform(0.0, 1.0) < 0.05 ? uniform(0.05, 5.0)   // a far row
                                                     : uniform(0.5e-3, 20e-3);
    t_ns_ += std::llround(step_s * 1e9);
    in.t_ns = t_ns_;
    const double wr = uniform(0.0, 1.0);
    in.window_s = wr < 0.2 ? 0.0 : wr < 0.25 ? uniform(0.0, 1.0) : std::max(0.0, step_s);
    in.u_reported_sq_pu = mode < 0.05 ? in.u_pu.squaredNorm() : (u + Vec2(gauss(noise), gauss(noise))).squaredNorm();
    if (uniform(0.0, 1.0) < 0.3) in.di_dt_pu_s = Vec2(gauss(1.0), gauss(1.0));
    // A speed rebuilt from a tracker's reads: its error, from nothing to far beyond the noise, now and then not finite
    // (drawn apart, so that the stream's other values are as they were without it).
    const auto draw = [this](double a, double b) { return std::uniform_real_distribution<double>(a, b)(speed_error_rng_); };
    const double speed_error = draw(0.0, 1.0);
    if (speed_error < 0.3) in.n_error_pu = std::pow(10.0, draw(-8.0, -1.0));
    if (speed_error < 0.2) in.n_error_noise_pu = std::pow(10.0, draw(-8.0, -1.0));
    if (speed_error > 0.7) in.n_reach_pu = std::abs(in.n_pu) * draw(0.5, 3.0);  // the reads' speeds, below and beyond
    if (speed_error < 0.001) {
      in.n_error_pu = kNaN;
    } else if (speed_error < 0.002) {
      in.n_error_pu = kInf;
    }
    const double g = uniform(0.0, 1.0);
    in.weight = g < 0.05 ? Vec2(0.0, 1.0) : g < 0.08 ? Vec2(2.0, 1e-12) : Vec2(uniform(0.0, 0.2), uniform(0.0, 0.2));

    // Rarely: a value that is not finite, or so large that differences overflow.
    const double bad = uniform(0.0, 1.0);
    if (bad < 0.003) {
      const std::array<double, 3> v{kNaN, kInf, -kInf};
      const double x = v[static_cast<std::size_t>(uniform(0.0, 2.999))];
      switch (static_cast<int>(uniform(0.0, 5.999))) {
        case 0:
          in.u_pu[1] = x;
          break;
        case 1:
          in.i_pu[0] = x;
          break;
        case 2:
          in.n_pu = x;
          break;
        case 3:
          in.u_reported_sq_pu = x;
          break;
        case 4:
          in.window_s = x;
          break;
        default:
          in.weight[1] = x;
          break;
      }
    } else if (bad < 0.005) {
      in.u_pu[0] = std::copysign(1.7e308, gauss(1.0));
      in.i_pu[1] = std::copysign(1.7e308, gauss(1.0));
    }
    return in;
  }

  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

 private:
  double gauss(double s) { return std::normal_distribution<double>(0.0, s)(rng_); }

  std::mt19937_64 rng_;
  std::mt19937_64 speed_error_rng_;
  double n_ = 0.4;
  Vec2 i_ = Vec2(-0.1, 0.5);
  Vec2 last_u_ = Vec2::Zero(), last_i_ = Vec2::Zero();
  double last_n_ = 0.0;
  std::int64_t t_ns_ = 1'000'000'000;
};

/// Both classifiers through `samples` of one stream; every output compared; the bits seen (the test is
/// not vacuous: each rule decides somewhere in it).
void run(const RegimeConfig& config, std::uint64_t seed, int samples) {
  RegimeClassifier now(config);
  test::reference::Classifier before(config);
  Stream stream(seed);
  std::array<std::uint64_t, 8> seen{};
  std::uint64_t flux_marks = 0;  // kPreviousMixed on a window that is not bridge off: the flux rule's
  for (int k = 0; k < samples; ++k) {
    const double event = stream.uniform(0.0, 1.0);
    if (event < 0.0005) {  // everything learnt forgotten: the noise medians warm up again (§13)
      now.reset();
      before = test::reference::Classifier(config);
    } else if (event < 0.002) {
      now.break_chain();
      before.break_chain();
    }
    const RegimeInput in = stream.next();
    const Classification a = now.step(in), b = before.step(in);
    ASSERT_EQ(a.bits, b.bits) << "sample " << k;
    ASSERT_EQ(a.regime, b.regime) << "sample " << k;
    ASSERT_TRUE(same(now.noise().u_sq, before.noise().u_sq) && same(now.noise().i_sq, before.noise().i_sq) &&
                same(now.noise().n_sq, before.noise().n_sq))
        << "sample " << k;
    ASSERT_TRUE(same(now.slope_pu_s(), before.slope_pu_s())) << "sample " << k;
    const RegimeNoise cn = now.current_noise(), cb = before.current_noise();
    ASSERT_TRUE(same(cn.u_sq, cb.u_sq) && same(cn.i_sq, cb.i_sq) && same(cn.n_sq, cb.n_sq)) << "sample " << k;
    for (std::size_t q = 0; q < 3; ++q) {
      ASSERT_TRUE(same(now.state().noise_median_pu[q], before.state().noise_median_pu[q])) << "sample " << k;
      ASSERT_TRUE(same(now.state().measured_resolution_pu[q], before.state().measured_resolution_pu[q])) << "sample " << k;
    }
    for (std::size_t bit = 0; bit < 8; ++bit) seen[bit] += (b.bits >> bit) & 1U;
    flux_marks += (b.bits & regime_bit::kPreviousMixed) && !(b.bits & regime_bit::kBridgeOff) ? 1U : 0U;
  }
  EXPECT_GT(flux_marks, 0U) << "the flux rule never marked a window";
  using namespace regime_bit;
  for (std::uint8_t bit : {kBridgeOff, kNotLocked, kTransient, kExcitesPsiM, kExcitesRs, kInvalid, kPreviousMixed}) {
    EXPECT_GT(seen[static_cast<std::size_t>(std::countr_zero(bit))], 0U) << "bit " << int{bit} << " never set";
  }
}

/// Samples per configuration. The sanitizer stage (scripts/test.sh: AddressSanitizer on a -O0 build, some 100
/// times slower) runs a prefix of the same streams: it looks for memory errors, which do not need millions of
/// samples; the optimised stage runs them all.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kSamplesPerConfig = 20'000;
#else
constexpr int kSamplesPerConfig = 1'000'000;
#endif

TEST(RegimeDifferential, TheCheaperClassifierDecidesAsTheDerivedRulesOnMillionsOfSamples) {
  const std::uint64_t seed = test::test_seed(23007);
  // The outrunner with measured resolution and with a configured one, and the paper's machine, their angles measured.
  EstimatorSettings outrunner = test::outrunner_settings();
  run(make_regime_config(test::outrunner_base(), test::outrunner_machine_si(), outrunner), seed, kSamplesPerConfig);
  outrunner.regimes.voltage_resolution_V = 0.01;
  outrunner.regimes.current_resolution_A = 0.01;
  outrunner.regimes.speed_resolution_rad_s = 0.1;
  run(make_regime_config(test::outrunner_base(), test::outrunner_machine_si(), outrunner), seed + 1, kSamplesPerConfig);
  EstimatorSettings paper = test::paper_settings(Algorithm::kSga);
  run(make_regime_config(test::paper_base(), test::paper_machine_si(), paper), seed + 2, kSamplesPerConfig);
  // Sensorless frames (r_s' test takes the frame error the lock test leaves possible): both machines.
  outrunner.regimes.sensorless = paper.regimes.sensorless = true;
  run(make_regime_config(test::outrunner_base(), test::outrunner_machine_si(), outrunner), seed + 3, kSamplesPerConfig);
  run(make_regime_config(test::paper_base(), test::paper_machine_si(), paper), seed + 4, kSamplesPerConfig);
}

/// A frame assumed a sensor's (angle_source not given): every decision a sensor's frame's, and the flag exactly where
/// r_s' term stands out for a sensor's frame and not for a sensorless one — three classifiers over one stream (the
/// frame's source enters only r_s' test, so the three learn the same state).
void run_assumed(EstimatorSettings settings, const PerUnitBase& base, const MachineSi& machine, std::uint64_t seed,
                 int samples) {
  settings.regimes.sensorless = false;
  RegimeClassifier sensor(make_regime_config(base, machine, settings));
  settings.regimes.angle_source_assumed = true;
  RegimeClassifier assumed(make_regime_config(base, machine, settings));
  settings.regimes.angle_source_assumed = false;
  settings.regimes.sensorless = true;
  RegimeClassifier sensorless(make_regime_config(base, machine, settings));
  Stream stream(seed);
  std::uint64_t flagged = 0, kept = 0;
  for (int k = 0; k < samples; ++k) {
    if (stream.uniform(0.0, 1.0) < 0.002) {
      for (RegimeClassifier* c : {&sensor, &assumed, &sensorless}) c->break_chain();
    }
    const RegimeInput in = stream.next();
    const Classification a = assumed.step(in), s = sensor.step(in), l = sensorless.step(in);
    const bool flag = (a.bits & regime_bit::kRsOnAssumedFrame) != 0;
    ASSERT_EQ(a.bits & ~regime_bit::kRsOnAssumedFrame, s.bits) << "sample " << k;
    ASSERT_EQ(a.regime, s.regime) << "sample " << k;
    ASSERT_EQ(flag, (s.bits & regime_bit::kExcitesRs) != 0 && (l.bits & regime_bit::kExcitesRs) == 0) << "sample " << k;
    // Besides R_s' test, the flux rule allows a sensorless frame its cone (§13, "A freewheel inside one window"): its
    // marks on windows that are not bridge off may differ; a release's (on a bridge-off window) may not.
    const std::uint8_t own = regime_bit::kExcitesRs | ((s.bits & regime_bit::kBridgeOff) ? 0 : regime_bit::kPreviousMixed);
    ASSERT_EQ(s.bits & ~own, l.bits & ~own) << "sample " << k;
    flagged += flag ? 1 : 0;
    kept += (s.bits & l.bits & regime_bit::kExcitesRs) != 0 ? 1 : 0;
  }
  // Not vacuous: the stream holds windows of both kinds.
  EXPECT_GT(flagged, 0U);
  EXPECT_GT(kept, 0U);
}

TEST(RegimeDifferential, AnAssumedFrameDecidesAsASensorsAndFlagsWhatOnlyItExcites) {
  const std::uint64_t seed = test::test_seed(23011);
  run_assumed(test::outrunner_settings(), test::outrunner_base(), test::outrunner_machine_si(), seed, kSamplesPerConfig / 4);
  run_assumed(test::paper_settings(Algorithm::kSga), test::paper_base(), test::paper_machine_si(), seed + 1,
              kSamplesPerConfig / 4);
}

}  // namespace
}  // namespace rpem::core
