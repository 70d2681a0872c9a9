// What the estimator tells the thermal filter (core/thermal_observer.hpp, docs/derivations.md §13) checked
// against the real estimator: the averaged estimator run on exact steady-state windows of a machine whose
// R_s is off the held value — its ψ̂m settles where eq. 13.6's κ says — and on windows with white current
// noise — the spread of ψ̂m is eq. 13.7's σ²_noise. The samples come from the machine equations directly
// (tests/support/averaged_data.hpp), not from the estimator's code.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "support/averaged_data.hpp"
#include "support/paper_machine.hpp"

namespace rpem::core {
namespace {

struct ObserverRun {
  std::vector<ThermalStepData> steps;
  std::vector<double> psi_m_Wb;  ///< ψ̂m after each sample
};

/// The paper machine's averaged estimator over `seconds` of 200 Hz windows at 0.8 pu speed and i = (−0.3, 0.9)
/// pu, the plant at `plant`, the estimator holding r̂s at its initial value; `noise_pu` white on the currents.
/// Calls `on_window(window, estimate)` for each.
template <class OnWindow>
void each_held_r_s_window(const MachinePu& plant, double seconds, double noise_pu, std::uint64_t seed, OnWindow on_window) {
  EstimatorSettings settings = test::paper_settings();
  settings.adapt_r_s = false;
  AveragedDriveEstimator estimator(test::paper_machine_si(), settings);
  test::AveragedDataGenerator gen;
  gen.base = test::paper_base();
  gen.plant = plant;
  gen.jitter = 0.0;
  gen.n_pu = [](double) { return 0.8; };
  gen.i_pu = [](double) { return Vec2(-0.3, 0.9); };
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_pu * gen.base.current_A);
  while (gen.t_s < seconds) {
    AveragedSample s = gen.next();
    if (noise_pu > 0.0) s.i_dq_A += Vec2(noise(rng), noise(rng));
    on_window(s, estimator.step(s));
  }
}

/// each_held_r_s_window's estimates through an observer of 1 s steps.
ObserverRun run(const MachinePu& plant, double seconds, double noise_pu, std::uint64_t seed) {
  const MachineSi machine = test::paper_machine_si();
  const PerUnitBase base = test::paper_base();
  ThermalObserverConfig oc;
  oc.period_s = 1.0;
  oc.residual_time_constant_s = 2.0;
  ThermalObserver observer(oc, base, machine, loss_base_of(base, machine), 25.0);
  ObserverRun out;
  std::int64_t previous = 0;
  each_held_r_s_window(plant, seconds, noise_pu, seed, [&](const AveragedSample& s, const Estimate& e) {
    ThermalSample ts;
    ts.dt_s = previous ? 1e-9 * static_cast<double>(s.t_ns - previous) : 0.0;
    previous = s.t_ns;
    if (observer.add(e, ts)) out.steps.push_back(observer.step());
    out.psi_m_Wb.push_back(e.psi_m_Wb);
  });
  return out;
}

TEST(ThermalObserver, HeldResistanceBiasesPsiMByKappaTimesItsError) {
  // The plant 20 % hotter in R_s (held at 2.25 Ω) and 4 % weaker in ψm: ψ̂m settles at ψm + κ·(R − r̂s).
  const PerUnitBase base = test::paper_base();
  MachinePu plant = test::paper_machine_pu();
  plant.r_s_pu *= 1.2;
  plant.psi_m_pu *= 0.96;
  const ObserverRun r = run(plant, 30.0, 0.0, 1);
  const ThermalStepData& last = r.steps.back();
  const ParameterObservation& p = last.parameter[kPsiM];
  ASSERT_TRUE(p.valid);
  EXPECT_FALSE(last.parameter[kRs].valid);  // r̂s does not adapt
  EXPECT_NEAR(p.other_held, 2.25, 1e-12);
  EXPECT_NEAR(p.sample_dt_s, 1.0 / 200.0, 1e-9);  // the adapted windows' mean length (eq. 14.25b): 200 Hz, no jitter
  const double psi_true = base.flux_Wb_of(plant.psi_m_pu), r_true = base.resistance_Ohm_of(plant.r_s_pu);
  const double bias = r.psi_m_Wb.back() - psi_true;
  // The linearised equilibrium of eq. 13.6 against the estimator's own: within 2 % of the bias.
  EXPECT_GT(std::abs(bias), 1e-3);
  EXPECT_NEAR(p.cross * (r_true - 2.25), bias, 0.02 * std::abs(bias));
  // In steady state the q equation says it: κ ≈ i_q/ω (ψ̂ = (u_q − r̂s·i_q)/ω − L_d·i_d), within the d row's share.
  EXPECT_NEAR(p.cross, 0.9 * base.current_A / (0.8 * base.omega_el_rad_s), 0.1 * std::abs(p.cross));
}

TEST(ThermalObserver, SpreadOfPsiMUnderWhiteCurrentNoiseIsTheNoiseVariance) {
  const MachinePu plant = test::paper_machine_pu();  // R_s exact: no held-parameter bias, ε̄ ≈ 0
  const ObserverRun r = run(plant, 240.0, 0.01, 7);
  // The estimator's spread after settling (the first 20 s dropped) against the observer's σ²_noise.
  double mean = 0.0, m2 = 0.0;
  std::size_t n = 0;
  for (std::size_t k = r.psi_m_Wb.size() / 12; k < r.psi_m_Wb.size(); ++k, ++n) {
    const double d = r.psi_m_Wb[k] - mean;
    mean += d / static_cast<double>(n + 1);
    m2 += d * (r.psi_m_Wb[k] - mean);
  }
  const double empirical = m2 / static_cast<double>(n - 1);
  double predicted = 0.0;
  std::size_t used = 0;
  for (std::size_t k = r.steps.size() / 12; k < r.steps.size(); ++k) {
    if (!r.steps[k].parameter[kPsiM].valid) continue;
    predicted += r.steps[k].parameter[kPsiM].variance_noise;
    ++used;
  }
  ASSERT_GT(used, 100u);
  predicted /= static_cast<double>(used);
  // ~1500 of the estimator's time constants: the empirical variance is good to about ±10 %; the batch means
  // keep 2/kBatch of the inductive correction's differenced noise, which adds a few per cent to the prediction.
  EXPECT_NEAR(empirical / predicted, 1.0, 0.25) << "empirical " << empirical << " predicted " << predicted;
}

TEST(ThermalObserver, NothingIsAnObservationBeforeTheEstimatorSettles) {
  const ObserverRun r = run(test::paper_machine_pu(), 3.0, 0.0, 1);
  ASSERT_FALSE(r.steps.empty());
  // Σa ≥ 5 over uninterrupted adaptation: with a ≈ γ_L per window the first steps cannot qualify.
  EXPECT_FALSE(r.steps.front().parameter[kPsiM].valid);
}

/// The winding sensor's readings of one step of the observer (1 s), each at its sample's time, `dt_s` apart.
ThermalStepData sensor_step(double dt_s) {
  const MachineSi machine = test::paper_machine_si();
  const PerUnitBase base = test::paper_base();
  ThermalObserver observer(ThermalObserverConfig{}, base, machine, loss_base_of(base, machine), 25.0);
  Estimate e;
  e.speed_pu = 0.5;
  e.i_meas_A = Vec2(1.0, 2.0);
  e.psi_m_Wb = machine.psi_m_Wb;
  ThermalSample s;
  s.dt_s = dt_s;
  for (int k = 1;; ++k) {
    s.winding_sensor_C = 60.0 + static_cast<double>(k);  // the k-th reading
    if (observer.add(e, s)) return observer.step();
  }
}

TEST(ThermalObserver, SensorReadingsAgeIsTheirTimesMeanAndSpreadAtTheStepsEnd) {
  // Rows 0.5 s apart: readings at 0.5 and 1 s of a 1 s step, each standing for 0.5 s — 0.25 s old on average,
  // variance 0.25², the mean reading the two readings' mean (eq. 14.22a, docs/derivations.md).
  const ThermalStepData two = sensor_step(0.5);
  EXPECT_NEAR(two.load.dt_s, 1.0, 1e-12);
  EXPECT_NEAR(two.winding_sensor_C, 61.5, 1e-12);
  EXPECT_NEAR(two.winding_sensor_age.mean_s, 0.25, 1e-12);
  EXPECT_NEAR(two.winding_sensor_age.variance_s2, 0.0625, 1e-12);
  // One row a step: a reading at the step's end.
  const ThermalStepData one = sensor_step(1.0);
  EXPECT_NEAR(one.winding_sensor_age.mean_s, 0.0, 1e-12);
  EXPECT_NEAR(one.winding_sensor_age.variance_s2, 0.0, 1e-12);
  // N = 1024 readings at k/N s (≈ 1 kHz, exact in binary) are (N − 1)/(2N) s old on average, variance
  // (N² − 1)/(12·N²) s² (a discrete uniform spread) — the continuous mean's Δt/2 and Δt²/12 as N grows.
  const double n = 1024.0;
  const ThermalStepData dense = sensor_step(1.0 / n);
  EXPECT_NEAR(dense.winding_sensor_age.mean_s, (n - 1.0) / (2.0 * n), 1e-12);
  EXPECT_NEAR(dense.winding_sensor_age.variance_s2, (n * n - 1.0) / (12.0 * n * n), 1e-12);
}

/// One 1 s step of eight samples 0.125 s apart (exact in binary), the coolant read at the samples `readings` names
/// (1–8; NaN elsewhere).
ThermalStepData coolant_step(ThermalObserver& observer, const std::vector<std::pair<int, double>>& readings) {
  Estimate e;
  e.speed_pu = 0.5;
  e.i_meas_A = Vec2(1.0, 2.0);
  e.psi_m_Wb = test::paper_machine_si().psi_m_Wb;
  for (int k = 1; k <= 8; ++k) {
    ThermalSample s;
    s.dt_s = 0.125;
    for (const auto& [at, value] : readings) {
      if (at == k) s.coolant_C = value;
    }
    if (observer.add(e, s)) {
      EXPECT_EQ(k, 8);
      return observer.step();
    }
  }
  ADD_FAILURE() << "no step in 1 s";
  return {};
}

TEST(ThermalObserver, ACoolantReadingHoldsUntilTheNextAndTheConfiguredOneStandsInBeforeTheFirst) {
  // The step's coolant is the time-weighted mean of what each sample stands for (eq. 14.1b's boundary): a sample
  // without a reading (a log's empty cell, a CAN sample whose coolant frame did not come) holds the newest reading.
  const MachineSi machine = test::paper_machine_si();
  const PerUnitBase base = test::paper_base();
  ThermalObserver observer(ThermalObserverConfig{}, base, machine, loss_base_of(base, machine), 25.0);
  // Each step says whether a reading came in it (the filter's coolant error starts again there, eq. 14.29).
  ThermalStepData s = coolant_step(observer, {});
  EXPECT_NEAR(s.load.coolant_C, 25.0, 1e-12);  // none yet: the configured one
  EXPECT_FALSE(s.coolant_read);
  s = coolant_step(observer, {{1, 31.0}});
  EXPECT_NEAR(s.load.coolant_C, 31.0, 1e-12);  // read once, held (not 25.75)
  EXPECT_TRUE(s.coolant_read);
  // Held at 31 over samples 1–4, read 37 at the 5th and held: (4·31 + 4·37)/8.
  s = coolant_step(observer, {{5, 37.0}});
  EXPECT_NEAR(s.load.coolant_C, 34.0, 1e-12);
  EXPECT_TRUE(s.coolant_read);
  s = coolant_step(observer, {});
  EXPECT_NEAR(s.load.coolant_C, 37.0, 1e-12);  // a step without a reading holds too
  EXPECT_FALSE(s.coolant_read);                // and is unread
}

/// The real estimator's estimates over `seconds` of noisy 200 Hz windows (ψ̂m settled, r̂s held), each with its Δt.
std::vector<Estimate> noisy_estimates(double seconds) {
  std::vector<Estimate> out;
  each_held_r_s_window(test::paper_machine_pu(), seconds, 0.01, 11,
                       [&](const AveragedSample&, const Estimate& e) { out.push_back(e); });
  return out;
}

/// How the observer is told of a mixed window inserted before estimate `at`: adapted and then taken back by the next
/// estimate (what the averaged estimator reports), taken back by a call before the next estimate (twice: what rpemd
/// does when a resynchronize() retracts), adapted and never taken back, or never adapted (excluded).
enum class MixedWindow { kRetracted, kRetractedByCall, kKept, kExcluded };

struct InsertedRun {
  std::vector<ThermalStepData> steps;
  bool inserted_completed_a_step = false;
};

InsertedRun observe_with_mixed_window(const std::vector<Estimate>& estimates, std::size_t at, MixedWindow how) {
  const MachineSi machine = test::paper_machine_si();
  const PerUnitBase base = test::paper_base();
  ThermalObserverConfig oc;
  oc.residual_time_constant_s = 2.0;
  ThermalObserver observer(oc, base, machine, loss_base_of(base, machine), 25.0);
  ThermalSample ts;
  ts.dt_s = 1.0 / 200.0;
  InsertedRun out;
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    Estimate e = estimates[k];
    if (k == at) {
      Estimate mixed = e;  // a freewheel half-way through: the flux read at 0.6 of it, a large residual
      mixed.psi_m_Wb *= 0.94;
      mixed.detail.epsilon_pu *= 40.0;
      mixed.epsilon_A *= 40.0;
      if (how == MixedWindow::kExcluded) mixed.detail.code = StepCode::kExcluded;
      const bool stepped = observer.add(mixed, ts);
      out.inserted_completed_a_step = stepped;
      if (stepped) out.steps.push_back(observer.step());
      e.retracted_previous = how == MixedWindow::kRetracted;
      if (how == MixedWindow::kRetractedByCall) {
        observer.retract_last();
        observer.retract_last();  // once: the second changes nothing
      }
    }
    if (observer.add(e, ts)) out.steps.push_back(observer.step());
  }
  return out;
}

void expect_same_observations(const ThermalStepData& a, const ThermalStepData& b, std::size_t step) {
  for (int j = 0; j < 2; ++j) {
    const ParameterObservation& p = a.parameter[static_cast<std::size_t>(j)];
    const ParameterObservation& q = b.parameter[static_cast<std::size_t>(j)];
    EXPECT_EQ(p.valid, q.valid) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.value, q.value) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.variance, q.variance) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.variance_noise, q.variance_noise) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.cross, q.cross) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.time_constant_s, q.time_constant_s) << "step " << step << " parameter " << j;
    EXPECT_EQ(p.sample_dt_s, q.sample_dt_s) << "step " << step << " parameter " << j;
  }
}

TEST(ThermalObserver, AWindowTakenBackByTheEstimatorIsTakenOutOfItsStepAsIfItHadNotAdapted) {
  // §13, "Mixed windows": the averaged estimator takes back what a window found mixed afterwards adapted
  // (Estimate::retracted_previous). The observer then holds every observation to the last bit as if that window had
  // been excluded — its value out of the step's mean, its a out of the settling, its residual out of ε̄ and Σ_ε.
  const std::vector<Estimate> estimates = noisy_estimates(20.0);
  const std::size_t at = 2400 + 37;  // mid-step, ψ̂m settled
  const InsertedRun retracted = observe_with_mixed_window(estimates, at, MixedWindow::kRetracted);
  const InsertedRun by_call = observe_with_mixed_window(estimates, at, MixedWindow::kRetractedByCall);
  const InsertedRun excluded = observe_with_mixed_window(estimates, at, MixedWindow::kExcluded);
  const InsertedRun kept = observe_with_mixed_window(estimates, at, MixedWindow::kKept);
  ASSERT_FALSE(retracted.inserted_completed_a_step);
  ASSERT_EQ(retracted.steps.size(), excluded.steps.size());
  ASSERT_EQ(by_call.steps.size(), excluded.steps.size());
  for (std::size_t k = 0; k < retracted.steps.size(); ++k) {
    expect_same_observations(retracted.steps[k], excluded.steps[k], k);
    expect_same_observations(by_call.steps[k], excluded.steps[k], k);
  }
  // Kept, the window moves its step's ψ̂m by its share (1 of 200 windows, 6 % low: 0.03 %) and the residual statistics.
  std::size_t step = 0;  // the step holding the window
  while (step < kept.steps.size() && kept.steps[step].t_ns < estimates[at].t_ns) ++step;
  ASSERT_LT(step + 1, kept.steps.size());
  ASSERT_TRUE(kept.steps[step].parameter[kPsiM].valid);
  const double shift = kept.steps[step].parameter[kPsiM].value / excluded.steps[step].parameter[kPsiM].value - 1.0;
  EXPECT_NEAR(shift, -0.06 / 201.0, 0.2 * 0.06 / 201.0);
  EXPECT_GT(kept.steps[step + 1].parameter[kPsiM].variance, excluded.steps[step + 1].parameter[kPsiM].variance);
}

TEST(ThermalObserver, AWindowTakenBackAfterItsStepCompletedLeavesThatStepAndLaterOnesLearnNothingOfIt) {
  // The window completed its step: the filter has had that step, so its sums stand; the settling and the residual
  // statistics after it are as if the window had been excluded, so every later step is.
  const std::vector<Estimate> estimates = noisy_estimates(20.0);
  std::size_t at = 2390;
  while (!observe_with_mixed_window(estimates, at, MixedWindow::kExcluded).inserted_completed_a_step) ++at;
  ASSERT_LT(at, 2410U);
  const InsertedRun retracted = observe_with_mixed_window(estimates, at, MixedWindow::kRetracted);
  const InsertedRun by_call = observe_with_mixed_window(estimates, at, MixedWindow::kRetractedByCall);
  const InsertedRun excluded = observe_with_mixed_window(estimates, at, MixedWindow::kExcluded);
  const InsertedRun kept = observe_with_mixed_window(estimates, at, MixedWindow::kKept);
  ASSERT_TRUE(retracted.inserted_completed_a_step);
  ASSERT_EQ(retracted.steps.size(), kept.steps.size());
  ASSERT_EQ(by_call.steps.size(), kept.steps.size());
  std::size_t completed = 0;  // the step the window completed
  while (completed < retracted.steps.size() && retracted.steps[completed].t_ns != estimates[at].t_ns) ++completed;
  ASSERT_LT(completed + 1, retracted.steps.size());
  expect_same_observations(retracted.steps[completed], kept.steps[completed], completed);
  expect_same_observations(by_call.steps[completed], kept.steps[completed], completed);
  for (std::size_t k = completed + 1; k < retracted.steps.size(); ++k) {
    expect_same_observations(retracted.steps[k], excluded.steps[k], k);
    expect_same_observations(by_call.steps[k], excluded.steps[k], k);
  }
  EXPECT_NE(kept.steps[completed + 1].parameter[kPsiM].variance, excluded.steps[completed + 1].parameter[kPsiM].variance);
}

}  // namespace
}  // namespace rpem::core
