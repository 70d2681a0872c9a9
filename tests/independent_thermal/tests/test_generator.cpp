// The generated log against its truth: determinism per seed, the row grid, noise and quantisation of the
// sensors, the voltages from the truth's own R_s and ψm, and the coolant modes.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "fixtures.hpp"
#include "indep_thermal/errors.hpp"
#include "indep_thermal/writers.hpp"

namespace indep_thermal {
namespace {

Case drive_cycle(std::uint64_t seed, double duration_s) {
  const Machine m = test::paderborn_machine();
  Case c;
  c.machine = m;
  c.params = draw_parameters(m, seed);
  c.profile = drive_cycle_profile(m, duration_s, seed);
  c.duration_s = duration_s;
  c.seed = seed;
  return c;
}

std::string log_text(const Result& r, LogColumns columns = {}) {
  std::ostringstream o;
  write_log_csv(o, r, columns);
  return o.str();
}

TEST(IndepThermalGenerator, DeterministicPerSeedAndOnTheRowGrid) {
  const Result a = generate(drive_cycle(61, 1200));
  const Result b = generate(drive_cycle(61, 1200));
  const Result c = generate(drive_cycle(62, 1200));
  EXPECT_EQ(log_text(a), log_text(b));
  EXPECT_NE(log_text(a), log_text(c));
  ASSERT_EQ(a.rows.size(), 2401u);
  for (std::size_t k = 0; k < a.rows.size(); ++k) EXPECT_EQ(a.rows[k].truth.t_s, 0.5 * static_cast<double>(k));
  std::ostringstream truth;
  write_truth_csv(truth, a);
  std::istringstream in(truth.str());
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("t,T_winding,T_iron,T_magnet,T_coolant,T_winding_sensor,r_s,r_s_ac,psi_m,", 0), 0u);
}

TEST(IndepThermalGenerator, ColumnsFollowTheFlagsAndTheNumbersDoNot) {
  const Result r = generate(drive_cycle(63, 60));
  EXPECT_EQ(log_text(r).substr(0, log_text(r).find('\n')), "t,i_d,i_q,u_d,u_q,omega_el,T_coolant,T_winding");
  const std::string bare = log_text(r, {false, false});
  EXPECT_EQ(bare.substr(0, bare.find('\n')), "t,i_d,i_q,u_d,u_q,omega_el");
  const std::string no_coolant = log_text(r, {false, true});
  EXPECT_EQ(no_coolant.substr(0, no_coolant.find('\n')), "t,i_d,i_q,u_d,u_q,omega_el,T_winding");
}

TEST(IndepThermalGenerator, MeasurementNoiseAndQuantisationAsConfigured) {
  const Case c = drive_cycle(64, 7200);
  const Result r = generate(c);
  const Parameters& p = c.params;
  const double sigma_i = p.noise_current_rel * p.rated_current_A;
  const double sigma_u = p.noise_voltage_rel * c.machine.peak_voltage_V();
  double si = 0, su = 0;
  for (const Row& row : r.rows) {
    si += std::pow(row.i_d_A - row.truth.op.i_d_A, 2) + std::pow(row.i_q_A - row.truth.op.i_q_A, 2);
    su += std::pow(row.u_d_V - row.truth.u.u_d_V, 2) + std::pow(row.u_q_V - row.truth.u.u_q_V, 2);
    // Sensors: multiples of their quantum, within 6σ + half a quantum of the truth.
    EXPECT_NEAR(std::round(row.t_winding_C * 10.0), row.t_winding_C * 10.0, 1e-9);
    EXPECT_NEAR(row.t_winding_C, row.truth.sensor_reading_C, 6 * p.sensor_winding_noise_K + 0.05);
    EXPECT_NEAR(row.t_coolant_C, row.truth.y(kTCoolant), 6 * p.sensor_coolant_noise_K + 0.05);
    EXPECT_EQ(row.omega_el_rad_s, row.truth.op.omega_el_rad_s);
  }
  // Sample σ over n = 2·14401 variates: relative standard error 1/√(2n) = 0.4 %; 2 % is 5 of them.
  const double n = 2.0 * static_cast<double>(r.rows.size());
  EXPECT_NEAR(std::sqrt(si / n), sigma_i, 0.02 * sigma_i);
  EXPECT_NEAR(std::sqrt(su / n), sigma_u, 0.02 * sigma_u);
}

TEST(IndepThermalGenerator, SensorLagsTheWinding) {
  // A step of current at standstill: the sensor's first-order lag, T_s(t) − T_w(t) solved here for the
  // winding's own early response, is checked as its defining equation dT_s/dt = (T_w − T_s)/τ by central
  // differences of the rows (10 Hz; error O(h²·T''') ≪ 1e-3 K/s).
  const Machine m = test::paderborn_machine();
  const Parameters p = draw_parameters(m, 65);
  const Case c = test::exact_case(m, p, test::constant_profile(0.0, 0.0, 200.0, 120.0), 120.0, 10.0);
  const Result r = generate(c);
  for (std::size_t k = 1; k + 1 < r.rows.size(); ++k) {
    const double slope = (r.rows[k + 1].truth.y(kTSensorLag) - r.rows[k - 1].truth.y(kTSensorLag)) / 0.2;
    const double law = (r.rows[k].truth.y(kTWinding) - r.rows[k].truth.y(kTSensorLag)) / p.sensor_winding_tau_s;
    EXPECT_NEAR(slope, law, 2e-3) << r.rows[k].truth.t_s;
  }
  EXPECT_GT(r.rows[100].truth.y(kTWinding) - r.rows[100].truth.y(kTSensorLag), 0.5);
}

TEST(IndepThermalGenerator, CoolantConstantOrLoop) {
  Case c = drive_cycle(66, 3600);
  c.coolant = CoolantMode::constant;
  for (const Row& row : generate(c).rows) EXPECT_EQ(row.truth.y(kTCoolant), c.params.coolant_start_C);
  c.coolant = CoolantMode::loop;
  double lo = 1e9, hi = -1e9;
  for (const Row& row : generate(c).rows) {
    lo = std::min(lo, row.truth.y(kTCoolant));
    hi = std::max(hi, row.truth.y(kTCoolant));
  }
  EXPECT_EQ(lo, c.params.coolant_start_C);
  EXPECT_GT(hi - lo, 2.0);
}

TEST(IndepThermalGenerator, HeatCoolOnThePaderbornMachineHeatsThenCools) {
  const Machine m = test::paderborn_machine();
  Case c = test::exact_case(m, draw_parameters(m, 67), heat_cool_profile(m, 7505), 7505, 0.1);
  const Result r = generate(c);
  const auto at = [&](double t) { return r.rows[static_cast<std::size_t>(t * 0.1)].truth; };
  const double t_step = 0.586 * 7505;
  EXPECT_GT(at(t_step - 10).y(kTWinding), at(t_step + 600).y(kTWinding) + 10.0);
  // The rotor lags: it is still warming 300 s into the heat-up, and cools more slowly than the winding.
  EXPECT_GT(at(600).y(kTRotor), at(300).y(kTRotor) + 1.0);
  const double winding_drop = at(t_step - 10).y(kTWinding) - at(t_step + 300).y(kTWinding);
  const double rotor_drop = at(t_step - 10).y(kTRotor) - at(t_step + 300).y(kTRotor);
  EXPECT_GT(winding_drop, 3.0 * rotor_drop);
  // The truth's R_s and ψm are the winding's and magnet's of the same row.
  const Snapshot s = at(3000);
  EXPECT_GT(s.r_s_dc_Ohm, c.params.r_s_ref_Ohm);
  EXPECT_LT(s.psi_m_Wb, c.params.psi_m_ref_Wb);
}

TEST(IndepThermalGenerator, ParametersJsonCarriesEveryKeyAndTheLaws) {
  const Case c = drive_cycle(68, 30);
  const Result r = generate(c);
  const nlohmann::json j = parameters_json(c, r, {});
  for (const CatalogueEntry& e : catalogue()) {
    EXPECT_EQ(j["parameters"][e.key].get<double>(), c.params.*e.field) << e.key;
    EXPECT_TRUE(j["nominal_parameters"].contains(e.key));
  }
  EXPECT_EQ(j["seed"], 68);
  EXPECT_EQ(j["rows"], r.rows.size());
  EXPECT_EQ(j["derived"]["time_constants_s_at_standstill"].size(), 3u);
  EXPECT_TRUE(j["laws"].contains("r_s"));
  EXPECT_EQ(j["summary"]["energy_residual_max_abs_J"].get<double>(), r.summary.max_abs_residual_J);
  EXPECT_EQ(j["summary"]["T_winding_max_C"].get<double>(), r.summary.t_winding_max_C);
}

TEST(IndepThermalGenerator, AveragedRowsAreWindowMeans) {
  // Window means from the integrals the plant carries, against the trapezoid rule over a 100 Hz run of the
  // same case (the truth at t), both for [t_k−1, t_k] of a 2 Hz averaged run; the trapezoid's error over a
  // window is bounded by the difference between its 100 Hz and 50 Hz estimates (order 2: the profile's
  // knots lie on the rows and it gives i_d, so no field-weakening square-root point is inside a window).
  const Machine m = test::paderborn_machine();
  Profile profile;
  profile.gives_i_d = true;
  profile.points = {{0, 0, 0, 0}, {20, 0, 100, -20}, {200, 0, 100, -20}, {220, 4000, 60, -120}, {600, 5000, 20, -80}};
  Case c = test::exact_case(m, draw_parameters(m, 70), profile, 600, 2);
  c.averaged = true;
  const Result avg = generate(c);
  Case fine = c;
  fine.averaged = false;
  fine.rate_Hz = 100.0;
  const Result inst = generate(fine);
  ASSERT_EQ(avg.rows.size(), 1201u);
  EXPECT_EQ(avg.rows[0].t_start_s, 0.0);
  EXPECT_EQ(avg.rows[0].u_q_V, avg.rows[0].truth.u.u_q_V);
  std::size_t checked = 0;
  for (std::size_t k = 1; k < avg.rows.size(); ++k) {
    const Row& a = avg.rows[k];
    EXPECT_EQ(a.t_start_s, avg.rows[k - 1].truth.t_s);
    double q100 = 0.0, q50 = 0.0;
    const std::size_t j0 = 50 * (k - 1);
    for (std::size_t j = j0; j < j0 + 50; ++j)
      q100 += 0.5 * (inst.rows[j].truth.u.u_q_V + inst.rows[j + 1].truth.u.u_q_V) / 50.0;
    for (std::size_t j = j0; j < j0 + 50; j += 2)
      q50 += (inst.rows[j].truth.u.u_q_V + inst.rows[j + 2].truth.u.u_q_V) / 50.0;
    EXPECT_NEAR(a.u_q_V, q100, std::abs(q50 - q100) + 1e-6 * (1.0 + std::abs(q100))) << a.truth.t_s;
    EXPECT_EQ(a.u_q_V, a.u_q_mean_V);
    checked += std::abs(a.truth.u.u_q_V - avg.rows[k - 1].truth.u.u_q_V) > 0.1;  // windows where u_q moved
  }
  EXPECT_GT(checked, 50u);
  std::ostringstream o;
  write_log_csv(o, avg, {true, true, true});
  EXPECT_EQ(o.str().substr(0, o.str().find('\n')), "t,t_start,i_d,i_q,u_d,u_q,omega_el,T_coolant,T_winding");
}

TEST(IndepThermalGenerator, SinkSeesEveryRowWithoutKeepingThem) {
  Case c = drive_cycle(71, 100);
  c.keep_rows = false;
  std::size_t n = 0;
  double last_t = -1.0;
  const Result r = generate(c, [&](const Row& row) {
    ++n;
    EXPECT_GT(row.truth.t_s, last_t);
    last_t = row.truth.t_s;
  });
  EXPECT_EQ(n, 201u);
  EXPECT_TRUE(r.rows.empty());
  EXPECT_EQ(r.summary.rows, 201u);
}

TEST(IndepThermalGenerator, BadCasesAreRefused) {
  Case c = drive_cycle(69, 10);
  c.rate_Hz = 0.0;
  EXPECT_THROW(generate(c), UsageError);
  c.rate_Hz = 2.0;
  c.duration_s = -1.0;
  EXPECT_THROW(generate(c), UsageError);
}

}  // namespace
}  // namespace indep_thermal
