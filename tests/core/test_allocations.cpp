// Zero heap allocations on the per-sample path: 10⁵ DriveEstimator::step() calls (conditioner,
// predictor, gradients, gains, update) for each algorithm and gradient form, and 10⁵
// AveragedDriveEstimator::step() calls for each algorithm, and 10⁵ ThermalFusion::step() calls, counted by
// replacing the global allocation functions in this test binary.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "support/averaged_data.hpp"
#include "support/model_data.hpp"
#include "support/outrunner_machine.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"
#include "support/regime_drive.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// The replacements below pair malloc with free; GCC cannot see that every path does.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace rpem::core {
namespace {

/// Steps the estimator over every sample, resets, freezes and steps once more, counting allocations.
template <typename Estimator, typename Sample>
void expect_no_allocations(Estimator& est, const std::vector<Sample>& samples) {
  const long before = g_allocations.load();
  double sink = 0.0;
  for (const Sample& s : samples) sink += est.step(s).psi_m_Wb;
  est.reset();
  est.set_frozen(true);
  sink += est.step(samples[0]).r_s_Ohm;
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
}

struct Case {
  Algorithm algorithm;
  GradientForm form;
  Discretization discretization;
};

class Allocations : public ::testing::TestWithParam<Case> {};

TEST_P(Allocations, NoneAcrossOneHundredThousandSteps) {
  const PerUnitBase base = test::paper_base();
  EstimatorSettings settings = test::paper_settings(GetParam().algorithm);
  settings.gradient_psi_m = settings.gradient_r_s = GetParam().form;
  settings.discretization = GetParam().discretization;
  // Every model extension on, so their per-sample paths are counted too.
  ModelExtensions& x = settings.extensions;
  x.deadtime_t_dead_s = 1e-6;
  x.switching_frequency_Hz = 4000.0;
  x.delay_s = 2.4 * 125e-6;  // whole and fractional periods: the command history
  x.theta_offset_rad = 0.02;
  x.current_offset_A = Vec3(0.05, 0.0, -0.02);
  x.current_gain_error = Vec3(0.01, 0.0, 0.0);
  x.inductance_q = {1.1, -0.002};
  x.iron_loss_r_fe_Ohm = 3000.0;
  x.cross_coupling_H_per_A = -1e-3;
  x.flux_harmonics[0] = {0.01, 0.0, 0.0, 0.01};
  x.flux_harmonics[1] = {0.0, 0.004, -0.002, 0.0};
  DriveEstimator est(test::paper_machine_si(), settings);
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = 0.3;
  gen.i_ref_pu = mtpa_reference(gen.plant, 0.4);
  // Pre-generate the samples so that only the estimator runs while counting.
  constexpr int kSteps = 100'000;
  std::vector<DriveSample> samples;
  samples.reserve(kSteps);
  std::int64_t t_ns = 0;
  for (int k = 0; k < kSteps; ++k) {
    samples.push_back(gen.next_si(base, t_ns));
    if (k % 20000 == 10000) gen.n_pu = 0.0;  // visit the r̂s region
    if (k % 20000 == 0) gen.n_pu = 0.3;
  }
  samples[5000].gap_before = true;
  samples[6000].i_A[0] = std::nan("");

  expect_no_allocations(est, samples);
}

INSTANTIATE_TEST_SUITE_P(EveryPath, Allocations,
                         ::testing::Values(Case{Algorithm::kSga, GradientForm::kSteadyState, Discretization::kTrapezoidal},
                                           Case{Algorithm::kSga, GradientForm::kDynamic, Discretization::kTrapezoidal},
                                           Case{Algorithm::kGna, GradientForm::kSteadyState, Discretization::kTrapezoidal},
                                           Case{Algorithm::kGna, GradientForm::kDynamic, Discretization::kExplicitEuler},
                                           Case{Algorithm::kPhyInt, GradientForm::kSteadyState,
                                                Discretization::kTrapezoidal}));

class AveragedAllocations : public ::testing::TestWithParam<Algorithm> {};

TEST_P(AveragedAllocations, NoneAcrossOneHundredThousandAveragedSteps) {
  // The averaged-sample path (steady-state model, inductive correction, rates per second) with every
  // extension it applies on, through gaps, a non-finite sample, standstill and speed.
  EstimatorSettings settings = test::paper_settings(GetParam());
  ModelExtensions& x = settings.extensions;
  x.deadtime_v_err_V = 2.0;
  x.delay_s = 100e-6;
  x.theta_offset_rad = 0.02;
  x.inductance_q = {1.1, -0.002};
  x.iron_loss_r_fe_Ohm = 3000.0;
  AveragedDriveEstimator est(test::paper_machine_si(), settings);
  test::AveragedDataGenerator gen;
  gen.base = test::paper_base();
  gen.plant = test::paper_machine_pu();
  gen.rate_Hz = 1000.0;
  gen.n_pu = [](double t) { return std::fmod(t, 20.0) < 10.0 ? 0.3 : 0.0; };
  gen.i_pu = [](double t) { return Vec2(-0.1, 0.3 + 0.1 * std::sin(t)); };
  gen.di_pu_per_s = [](double t) { return Vec2(0.0, 0.1 * std::cos(t)); };
  constexpr int kSteps = 100'000;
  std::vector<AveragedSample> samples;
  samples.reserve(kSteps);
  for (int k = 0; k < kSteps; ++k) samples.push_back(gen.next());
  samples[5000].gap_before = true;
  samples[6000].i_dq_A[0] = std::nan("");

  expect_no_allocations(est, samples);
}

INSTANTIATE_TEST_SUITE_P(EveryAlgorithm, AveragedAllocations,
                         ::testing::Values(Algorithm::kSga, Algorithm::kGna, Algorithm::kPhyInt));

TEST(RegimeAllocations, NoneThroughEveryRegimeAndTheSparsePath) {
  // The classifier alone; the averaged estimator through every regime (open loop, bridge off, coasting,
  // transients, an outlier); DriveEstimator on sparse rows (steady-state observations) among dense ones.
  test::RegimeDrive drive;
  drive.psi_m_Wb *= 0.9;
  const Vec2 zero = Vec2::Zero(), q(0.0, 20.0);
  std::vector<test::DriveSegment> cycle{
      {3.0, test::DriveMode::kOpenLoop, 0.0, 400.0, q, q, 1.2},
      {5.0, test::DriveMode::kClosedLoop, 400.0, 1500.0, q, q},
      {5.0, test::DriveMode::kBridgeOff, 1500.0, 1400.0, zero, zero},
      {5.0, test::DriveMode::kCoast, 1400.0, 1300.0, zero, zero},
      {5.0, test::DriveMode::kClosedLoop, 0.0, 0.0, q, q},
  };
  std::vector<AveragedSample> windows;
  while (windows.size() < 20'000) {
    for (const auto& w : drive.windows(cycle)) {
      AveragedSample s = w.sample;
      const std::int64_t shift = windows.empty() ? 0 : windows.back().t_ns;
      s.t_start_ns += shift;
      s.t_ns += shift;
      windows.push_back(s);
    }
  }
  windows[777].i_dq_A[1] += 500.0;  // an outlier
  AveragedDriveEstimator averaged(test::outrunner_machine_si(), test::outrunner_settings());
  expect_no_allocations(averaged, windows);

  RegimeClassifier classifier(
      make_regime_config(test::outrunner_base(), test::outrunner_machine_si(), test::outrunner_settings()));
  std::vector<RegimeInput> inputs;
  for (const AveragedSample& w : windows) {
    RegimeInput in;
    in.timing = SampleTiming::kContiguous;
    in.t_ns = w.t_ns;
    in.window_s = 1e-9 * static_cast<double>(w.t_ns - w.t_start_ns);
    in.u_pu = w.u_dq_V / 10.0;
    in.i_pu = w.i_dq_A / 50.0;
    in.n_pu = w.omega_el_rad_s / 4000.0;
    in.u_reported_sq_pu = in.u_pu.squaredNorm();
    in.weight = Vec2::Constant(0.01);
    inputs.push_back(in);
  }
  const long before = g_allocations.load();
  unsigned sink = 0;
  for (const RegimeInput& in : inputs) sink += classifier.step(in).bits;
  classifier.reset();
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(sink, 0U);

  const PerUnitBase base = test::paper_base();
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = base.omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = mtpa_reference(gen.plant, 0.4);
  std::vector<DriveSample> rows;
  std::int64_t t_ns = 0, offset_ns = 0;
  for (int k = 0; k < 50'000; ++k) {
    DriveSample s = gen.next_si(base, t_ns);
    if (k % 10 == 0) offset_ns += 2'500'000'000;  // a bench's rows, seconds apart, among dense ones
    s.t_ns += offset_ns;
    if (k % 1000 == 500) s.u_V.setZero(), s.i_A.setZero();  // bridge off
    rows.push_back(s);
  }
  DriveEstimator sparse(test::paper_machine_si(), test::paper_settings());
  expect_no_allocations(sparse, rows);
}

TEST(ThermalAllocations, NoneAcrossOneHundredThousandFusedSteps) {
  // The thermal fusion beside the estimator (rpemd's loop and `rpem estimate --thermal`): loss accumulation,
  // observations, a 3-node network's exact step every 1 ms (so the filter steps 10⁴ times), gate resets,
  // coasting without samples, a reload (to the reading node of eq. 14.24), a non-finite sample and a sensor that
  // holds one value (eq. 14.28); one node's disturbance Gauss–Markov.
  const MachineSi machine = test::paper_machine_si();
  AveragedDriveEstimator est(machine, test::paper_settings());
  ThermalFusionConfig c = test::paper_thermal_fusion();
  c.filter.disturbance_time_constant_s[0] = 600.0;  // one Gauss–Markov disturbance (eq. 14.19) beside the walks
  c.winding_sensor_time_constant_s = 10.0;          // the lagging sensor's observation and lag (eq. 14.22) too
  ThermalFusion fusion(c, test::paper_base(), machine);
  // The reload switches the winding node to the sensor's reading (eq. 14.24): both forms run here.
  ThermalFusionConfig reading = c;
  reading.winding_node_is_reading = true;
  test::AveragedDataGenerator gen;
  gen.base = test::paper_base();
  gen.plant = test::paper_machine_pu();
  gen.rate_Hz = 1000.0;
  gen.n_pu = [](double t) { return std::fmod(t, 20.0) < 10.0 ? 0.8 : 0.0; };
  gen.i_pu = [](double t) { return Vec2(-0.2, 0.6 + 0.1 * std::sin(t)); };
  constexpr int kSteps = 100'000;
  std::vector<AveragedSample> samples;
  samples.reserve(kSteps);
  for (int k = 0; k < kSteps; ++k) samples.push_back(gen.next());
  samples[6000].i_dq_A[0] = std::nan("");
  const long before = g_allocations.load();
  double sink = 0.0;
  int withdrawn_steps = 0;  // refused by eq. 14.28 after the held value had been taken (so withdrawn)
  std::int64_t previous = samples.front().t_ns;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Estimate e = est.step(samples[k]);
    ThermalSample s;
    s.dt_s = 1e-9 * static_cast<double>(samples[k].t_ns - previous);
    // For the first 20 000 steps the sensor holds 0 °C (a disabled input: the start takes it, the check withdraws it
    // and refuses it, eq. 14.28), from 60 000 one value 40 K below the winding (the gate's refusals, no reset).
    const double reading_C = k < 20'000 ? 0.0 : k < 60'000 ? 60.0 + 1e-4 * static_cast<double>(k) : 20.0;
    s.winding_sensor_C = k % 50 == 0 ? reading_C : std::nan("");
    s.coolant_C = 40.0;
    previous = samples[k].t_ns;
    fusion.step(e, s);
    if (k == 50'000) fusion.reconfigure(reading, test::paper_base(), machine);
    if (k % 20'000 == 0) fusion.coast(0.5);
    sink += fusion.estimate().magnet_node().t_C;
    withdrawn_steps += k < 20'000 && fusion.last_observations()[2].result == ObservationResult::kRejectedHeld ? 1 : 0;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));
  EXPECT_GT(fusion.estimate().observations_accepted, 1000);
  EXPECT_GT(fusion.estimate().winding_readings_held, 0);
  EXPECT_GT(withdrawn_steps, 0);
}

TEST(AllocationCounter, CountsAnAllocation) {
  // Guard against a counter that cannot fail.
  const long before = g_allocations.load();
  auto* p = new std::vector<int>(100);
  // Let the buffer escape: GCC may elide std::allocator's allocation (__builtin_operator_new) of a vector
  // nothing uses, as it did once this file grew (issue 23).
  asm volatile("" : : "g"(p->data()) : "memory");
  delete p;
  EXPECT_GE(g_allocations.load() - before, 2);
}

}  // namespace
}  // namespace rpem::core
