// The averaged-sample estimator on simulated averaged data at 50, 200 and 1000 Hz (issue 12, item 1):
// ψm within 1 % and R_s within 3 % where the scheduler lets them adapt, on data from our simulator and
// from the independent generator (tests/independent_drive: its own plant, controller, sensors and
// averaging; the true machine off the configuration). One profile for both: standstill under three loads
// with steps between them (R_s adapts below n_lim,2), then 500 and 700 rpm with ramps and torque steps
// (ψm adapts above n_lim,1); R_s is judged at the end of the standstill, ψm at the end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "indep_drive/generator.hpp"
#include "rpem/core/averaged_estimator.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/sim/cycle_average.hpp"
#include "rpem/sim/drive_simulator.hpp"
#include "support/temp_file.hpp"

namespace rpem {
namespace {

constexpr double kPsiRel = -0.06;  // true ψm = configured · (1 + this)
constexpr double kRsRel = 0.18;    // true R_s = configured · (1 + this)
constexpr double kStandstillEnd_s = 14.0;
constexpr double kDuration_s = 20.0;
constexpr double kTorque_Nm = 16.3;  // 0.5 of rated

std::string paper_config() { return test::source_dir() + "/config/paper-ipmsm.yaml"; }

/// The profile: (t [s], speed [rpm], torque [Nm]) breakpoints, linear between, a repeated time a step.
struct Point {
  double t_s, speed_rpm, torque_Nm;
};
const std::vector<Point>& profile() {
  static const std::vector<Point> p = {
      {0.0, 0, kTorque_Nm},    {4.0, 0, kTorque_Nm},    {4.0, 0, 24.0},        {8.0, 0, 24.0},
      {8.0, 0, 10.0},          {11.0, 0, 10.0},         {11.0, 0, kTorque_Nm}, {kStandstillEnd_s, 0, kTorque_Nm},
      {14.5, 500, kTorque_Nm}, {16.0, 500, kTorque_Nm}, {16.0, 500, 24.0},     {17.0, 500, 24.0},
      {17.5, 700, 24.0},       {18.5, 700, 24.0},       {18.5, 700, 10.0},     {kDuration_s, 700, 10.0}};
  return p;
}

/// The profile as our scenario's events.
std::string scenario_events() {
  std::string e;
  char line[160];
  const auto& p = profile();
  for (std::size_t k = 1; k < p.size(); ++k) {
    if (p[k].t_s == p[k - 1].t_s && p[k].torque_Nm != p[k - 1].torque_Nm) {
      std::snprintf(line, sizeof line, "  - {t_s: %g, quantity: torque_Nm, kind: step, value: %g}\n", p[k].t_s,
                    p[k].torque_Nm);
      e += line;
    }
    if (p[k].speed_rpm != p[k - 1].speed_rpm) {
      std::snprintf(line, sizeof line, "  - {t_s: %g, quantity: speed_rpm, kind: ramp, value: %g, duration_s: %g}\n",
                    p[k - 1].t_s, p[k].speed_rpm, p[k].t_s - p[k - 1].t_s);
      e += line;
    }
  }
  return e;
}

/// The profile as the independent generator's breakpoints.
std::vector<indep::ProfilePoint> profile_points() {
  std::vector<indep::ProfilePoint> out;
  for (const Point& p : profile()) out.push_back({p.t_s, p.speed_rpm, p.torque_Nm, 0.0});
  return out;
}

struct Result {
  double psi_m_rel_error = 0.0;  ///< at the end (ψm adapting since 14.5 s)
  double r_s_rel_error = 0.0;    ///< at the end of the standstill
  std::size_t samples = 0;
};

Result estimate(const std::vector<core::AveragedSample>& samples, double true_psi_m, double true_r_s) {
  const io::MachineConfig cfg = io::load_machine_config(paper_config());
  core::AveragedDriveEstimator est(cfg.machine, cfg.estimator);
  Result r;
  for (const core::AveragedSample& s : samples) {
    (void)est.step(s);
    if (s.t_ns <= static_cast<std::int64_t>(kStandstillEnd_s * 1e9)) r.r_s_rel_error = est.r_s_Ohm() / true_r_s - 1.0;
  }
  r.psi_m_rel_error = est.psi_m_Wb() / true_psi_m - 1.0;
  r.samples = samples.size();
  return r;
}

/// Our simulator: switching inverter, noisy quantised sensors, the drive's per-cycle averages.
std::vector<core::AveragedSample> our_simulator(double rate_Hz) {
  char text[1024];
  std::snprintf(text, sizeof text,
                "name: averaged-accuracy\nmachine: %s\nduration_s: %g\nseed: 3\n"
                "inverter: {model: switching, switching_frequency_Hz: 4000}\n"
                "sensors: {current_noise_A: 0.02, current_lsb_A: 0.005, encoder_counts: 16384}\n"
                "initial: {psi_m_Wb: %.6f, r_s_Ohm: %.6f, speed_rpm: 0, torque_Nm: %g, u_dc_V: 565}\n"
                "events:\n%s",
                paper_config().c_str(), kDuration_s, 1.14 * (1 + kPsiRel), 2.25 * (1 + kRsRel), kTorque_Nm,
                scenario_events().c_str());
  sim::DriveSimulator simulator(sim::parse_scenario(text, "averaged-accuracy", test::source_dir()));
  sim::CycleExtractor cycles;
  sim::WindowAverager windows(rate_Hz, 0.3, 11);
  std::vector<core::AveragedSample> out;
  io::DriveLogRow row;
  sim::TruthRow truth;
  while (simulator.next(row, truth)) {
    if (const auto c = cycles.add(row)) {
      if (const auto w = windows.add(*c)) out.push_back(*w);
    }
  }
  return out;
}

/// The independent generator in its averaged mode (README "Averaged"), `source` drive or plant.
std::vector<core::AveragedSample> independent(double rate_Hz, indep::AveragedSource source) {
  indep::Case c;
  c.machine = indep::read_machine_config(paper_config());
  c.seed = 5;
  c.duration_s = kDuration_s;
  c.draw.psi_m_rel = kPsiRel;
  c.draw.r_s_rel = kRsRel;
  c.profile.points = profile_points();
  c.averaged.on = true;
  c.averaged.rate_Hz = rate_Hz;
  c.averaged.source = source;
  c.keep_log_rows = false;
  c.keep_plant_rows = false;
  const indep::Result result = indep::generate(c);
  EXPECT_NEAR(result.truth.true_machine.psi_m_Wb, 1.14 * (1 + kPsiRel), 1e-9);
  EXPECT_NEAR(result.truth.true_machine.r_s_Ohm, 2.25 * (1 + kRsRel), 1e-9);
  std::vector<core::AveragedSample> out;
  for (const indep::AveragedRow& a : result.averaged) {
    core::AveragedSample s;
    s.t_start_ns = std::llround(a.t_start_s * 1e9);
    s.t_ns = std::llround(a.t_s * 1e9);
    s.i_dq_A = {a.i_d_A, a.i_q_A};
    s.u_dq_V = {a.u_d_V, a.u_q_V};
    s.omega_el_rad_s = a.omega_el_rad_s;
    s.u_dc_V = a.u_dc_V;
    out.push_back(s);
  }
  return out;
}

class AveragedAccuracy : public ::testing::TestWithParam<double> {};

void check(const char* source, double rate, const Result& r) {
  std::printf("[ accuracy ] %-22s %5.0f Hz: %6zu samples, psi_m %+.3f %%, R_s %+.3f %%\n", source, rate, r.samples,
              100.0 * r.psi_m_rel_error, 100.0 * r.r_s_rel_error);
  EXPECT_LT(std::abs(r.psi_m_rel_error), 0.01) << source << " at " << rate << " Hz";
  EXPECT_LT(std::abs(r.r_s_rel_error), 0.03) << source << " at " << rate << " Hz";
  // The configuration is 6 % (ψm) and 18 % (R_s) off the truth, so passing needs adaptation; and the
  // source delivered its rate.
  EXPECT_GT(r.samples, static_cast<std::size_t>(0.8 * rate * kDuration_s));
}

TEST_P(AveragedAccuracy, OurSimulator) {
  check("rpem sim", GetParam(), estimate(our_simulator(GetParam()), 1.14 * (1 + kPsiRel), 2.25 * (1 + kRsRel)));
}

TEST_P(AveragedAccuracy, IndependentGeneratorDriveAverages) {
  check("indep (drive averages)", GetParam(),
        estimate(independent(GetParam(), indep::AveragedSource::drive), 1.14 * (1 + kPsiRel), 2.25 * (1 + kRsRel)));
}

TEST_P(AveragedAccuracy, IndependentGeneratorPlantAverages) {
  check("indep (plant averages)", GetParam(),
        estimate(independent(GetParam(), indep::AveragedSource::plant), 1.14 * (1 + kPsiRel), 2.25 * (1 + kRsRel)));
}

INSTANTIATE_TEST_SUITE_P(Rates, AveragedAccuracy, ::testing::Values(50.0, 200.0, 1000.0),
                         [](const auto& p) { return std::to_string(static_cast<int>(p.param)) + "Hz"; });

}  // namespace
}  // namespace rpem
