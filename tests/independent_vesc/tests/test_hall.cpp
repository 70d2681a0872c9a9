// Hall mode (README "Hall mode"), against numbers derived here rather than read back from the implementation:
//  - the sensors: six states, 60° apart, one bit per edge, edges at φ_0 + 30° + m·60°;
//  - the detected table: each state's sector centre φ_0 + m·60°, less the table's truncation to 1/200 turn (1.8°) and
//    within the 1° sweep's half degree: table angle − centre ∈ [−2.3°, +0.5°] (δ below);
//  - crawling (below foc_hall_interp_erpm): the frame is the state's table angle, or on its way there from the
//    previous one at 1.5·foc_hall_interp_erpm (the rate limit); |ε| ≤ π/6 + 2.3° + ωT (the rotor anywhere in its
//    sector, the transition seen at the first sample after the edge);
//  - interpolated at a constant speed: at each transition the frame is set to the two table angles' midpoint (the
//    edge within 2.3° + 0.9° of integer halving = 3.2°) and runs on at the last sector's speed (the sector's time
//    counted in whole periods: within ωT over a sector), seen up to a period late: |ε| ≤ 3.2° + 2ωT;
//  - blended with the observer's angle linearly in the PLL's speed between foc_sl_erpm_start and foc_sl_erpm, the
//    observer's alone above;
//  - the generator and the CLI: the same bounds on the emulated drive, and its truth.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "fixtures.hpp"
#include "indep_vesc/hall.hpp"
#include "indep_vesc/observer.hpp"

namespace indep::vesc {
namespace {

using testing::outrunner_case;
using testing::rows_between;
using testing::segment;

constexpr double kDeg = kPi / 180.0;
constexpr double kT = 80e-6;                   // the control period at f_zv = 25 kHz
constexpr double kTableError = 2.3 * kDeg;     // δ: truncation (1.8°) + the sweep's half degree
constexpr double kMidpointError = 3.2 * kDeg;  // δ + integer halving (0.9°)
double erpm_to_rad_s(double erpm) { return erpm * 2.0 * kPi / 60.0; }

/// The crawl bound: the rotor anywhere in its 60° sector, the frame at its table angle (or between the previous
/// and the new one right after a transition), the transition seen up to a period late.
double crawl_bound(double omega) { return kPi / 6.0 + kTableError + std::fabs(omega) * kT + 1e-6; }

TEST(IndepVescHall, SensorsSwitchEverySixtyDegreesOneBitAtATime) {
  for (const double offset_deg : {0.0, 37.0, -100.0, 213.4}) {
    const double offset = offset_deg * kDeg;
    const int steps = 360000;  // 0.001°
    int transitions = 0;
    int previous = hall_state(0.0, offset);
    for (int k = 1; k <= steps; ++k) {
      const double theta = k * 2.0 * kPi / steps;
      const int state = hall_state(theta, offset);
      ASSERT_NE(state, 0);
      ASSERT_NE(state, 7);
      if (state != previous) {
        ++transitions;
        const int changed = state ^ previous;
        EXPECT_TRUE(changed == 1 || changed == 2 || changed == 4) << "one sensor at a time";
        // Edges at φ_0 + 30° + m·60°.
        const double from_edge = std::remainder(theta - offset - kPi / 6.0, kPi / 3.0);
        EXPECT_LT(std::fabs(from_edge), 2e-5) << offset_deg << "° at " << theta / kDeg;
        // Forwards the state's sector centre is 60° on from the previous one's.
        EXPECT_NEAR(wrap_pi(hall_sector_centre_rad(state, offset) - hall_sector_centre_rad(previous, offset)), kPi / 3.0,
                    1e-12);
      }
      previous = state;
    }
    EXPECT_EQ(transitions, 6);
    // The centre of each sector reads that sector's state.
    for (int m = 0; m < 6; ++m) {
      const int state = hall_state(offset + m * kPi / 3.0, offset);
      EXPECT_NEAR(wrap_pi(hall_sector_centre_rad(state, offset) - offset - m * kPi / 3.0), 0.0, 1e-12);
    }
  }
}

TEST(IndepVescHall, DetectionFindsEachSectorsCentre) {
  for (const double offset_deg : {0.0, 17.3, 37.0, 45.0, -100.0, 213.4, 359.9}) {
    const double offset = offset_deg * kDeg;
    const std::array<int, 8> table = detect_hall_table(offset);
    EXPECT_EQ(table[0], kHallInvalid);
    EXPECT_EQ(table[7], kHallInvalid);
    for (int state = 1; state <= 6; ++state) {
      ASSERT_GE(table[state], 0);
      ASSERT_LT(table[state], 200);
      const double error = wrap_pi(table[state] * 2.0 * kPi / 200.0 - hall_sector_centre_rad(state, offset));
      EXPECT_GE(error, -kTableError - 1e-9) << offset_deg << "° state " << state;
      EXPECT_LE(error, 0.5 * kDeg + 1e-9) << offset_deg << "° state " << state;
    }
  }
}

HallSettings settings_for(double offset) {
  HallSettings s;
  s.table = detect_hall_table(offset);
  return s;  // foc_hall_interp_erpm 500, foc_sl_erpm_start 2500, foc_sl_erpm 3500 (mcconf_default.h)
}

/// Runs the Hall angle for a rotor at θ(t) = θ0 + ∫ω, the PLL taken at the true speed, the observer's angle far off.
struct HallRun {
  std::vector<double> t, theta, error, out;
  std::vector<int> state;
  std::vector<bool> nearest;
};
HallRun run_hall(HallAngle& h, double offset, double theta0, double seconds, double (*omega_of_t)(double)) {
  HallRun r;
  double theta = theta0;
  for (int k = 0; k * kT < seconds; ++k) {
    const double t = k * kT;
    const double w = omega_of_t(t);
    const int state = hall_state(theta, offset);
    const double out = h.correct(theta + 2.0, w, state, kT);
    r.t.push_back(t);
    r.theta.push_back(theta);
    r.out.push_back(out);
    r.error.push_back(wrap_pi(out - theta));
    r.state.push_back(state);
    r.nearest.push_back(h.nearest());
    theta += w * kT;
  }
  return r;
}

TEST(IndepVescHall, CrawlingTheFrameIsTheStatesTableAngle) {
  const double offset = 37.0 * kDeg;
  const HallSettings s = settings_for(offset);
  // The rate limit: 1.5·foc_hall_interp_erpm; a 60° (+2δ) step takes t_ramp.
  const double t_ramp = (kPi / 3.0 + 2.0 * kTableError) / (1.5 * erpm_to_rad_s(500.0));
  for (const double erpm : {60.0, -45.0, 250.0}) {
    static double w_now;
    w_now = erpm_to_rad_s(erpm);
    HallAngle h(s);
    const HallRun r = run_hall(h, offset, 1.0, 3.0, [](double) { return w_now; });
    double worst = 0.0, last_transition = -1.0;
    int on_table = 0, checked = 0;
    for (std::size_t k = 1; k < r.t.size(); ++k) {
      if (r.state[k] != r.state[k - 1]) last_transition = r.t[k];
      if (r.t[k] < 0.05) continue;  // the rate-limited angle catches up from 0 first (≤ π at 78.5 rad/s: 40 ms)
      ++checked;
      ASSERT_TRUE(r.nearest[k]);
      worst = std::max(worst, std::fabs(r.error[k]));
      ASSERT_LE(std::fabs(r.error[k]), crawl_bound(w_now)) << erpm << " ERPM at " << r.t[k];
      const double table_angle = s.table[r.state[k]] * 2.0 * kPi / 200.0;
      if (r.t[k] - last_transition > t_ramp + kT) {
        ASSERT_NEAR(wrap_pi(r.out[k] - table_angle), 0.0, 1e-9) << "settled on the state's angle at " << r.t[k];
        ++on_table;
      }
    }
    // Across a sector the error sweeps from −30° to +30° about δ: its largest magnitude reaches ~30°.
    EXPECT_GT(worst, kPi / 6.0 - kTableError - 0.02) << erpm;
    EXPECT_GT(on_table, 0.5 * checked) << erpm;
  }
}

TEST(IndepVescHall, CrawlingThroughAReversalStaysWithinHalfASector) {
  const double offset = 0.0;
  HallAngle h(settings_for(offset));
  // 80 ERPM forwards, then backwards, swinging over four sectors and back.
  const HallRun r =
      run_hall(h, offset, 0.3, 4.0, [](double t) { return erpm_to_rad_s(80.0) * std::cos(2.0 * kPi * t / 2.0); });
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    if (r.t[k] < 0.05) continue;
    ASSERT_LE(std::fabs(r.error[k]), crawl_bound(erpm_to_rad_s(80.0))) << r.t[k];
  }
}

TEST(IndepVescHall, InterpolatedAtAConstantSpeedTheErrorIsSmall) {
  const double offset = 37.0 * kDeg;
  const HallSettings s = settings_for(offset);
  for (const double erpm : {800.0, 1500.0, -2000.0}) {
    static double w_now;
    w_now = erpm_to_rad_s(erpm);
    HallAngle h(s);
    const HallRun r = run_hall(h, offset, 0.2, 0.5, [](double) { return w_now; });
    // From one turn on: the first transition sets the direction, the second the sector time (interpolation starts);
    // a rotor at this speed from the start leaves the rate-limited angle behind until then (it follows the states at
    // 1.5·foc_hall_interp_erpm only), and that lag closes at half the Hall speed (its limit is 1.5×) over sectors.
    int transitions = 0;
    double sum_abs = 0.0;
    int n = 0;
    const double bound = kMidpointError + 2.0 * std::fabs(w_now) * kT + 1e-6;
    for (std::size_t k = 1; k < r.t.size(); ++k) {
      if (r.state[k] != r.state[k - 1]) ++transitions;
      if (transitions < 8) continue;
      ASSERT_FALSE(r.nearest[k]) << erpm;
      ASSERT_LE(std::fabs(r.error[k]), bound) << erpm << " ERPM at " << r.t[k];
      sum_abs += std::fabs(r.error[k]);
      ++n;
    }
    ASSERT_GT(n, 1000);
    EXPECT_LT(sum_abs / n, 0.5 * bound) << erpm;
  }
}

// A fast stop and a reversal: on the first transition the other way the firmware keeps the last sector's time and
// flips only its sign, so for foc_hall_interp_erpm's 20 ms the angle runs backwards at the old speed until it is held
// 30° past the state's angle: the frame up to 60° off the rotor; then the nearest state's angle again.
TEST(IndepVescHall, AReversalAfterAFastStopInterpolatesAtTheStaleSpeed) {
  const double offset = 37.0 * kDeg;
  HallAngle h(settings_for(offset));
  const HallRun r = run_hall(h, offset, 0.0, 1.4, [](double t) {
    return t < 0.1 ? erpm_to_rad_s(1500.0) : t < 0.4 ? 0.0 : erpm_to_rad_s(-40.0);
  });
  std::size_t reverse = 0;
  for (std::size_t k = 1; k < r.t.size() && reverse == 0; ++k) {
    if (r.t[k] > 0.4 && r.state[k] != r.state[k - 1]) reverse = k;
  }
  ASSERT_GT(reverse, 0u) << "no transition backwards";
  const double stale = (kPi / 3.0) / erpm_to_rad_s(500.0);  // 20 ms
  const double t_ramp = (kPi / 3.0 + 2.0 * kTableError) / (1.5 * erpm_to_rad_s(500.0));
  double worst_stale = 0.0;
  for (std::size_t k = reverse; k < r.t.size(); ++k) {
    const double since = r.t[k] - r.t[reverse];
    ASSERT_LE(std::fabs(r.error[k]), kPi / 3.0 + kMidpointError + 1e-6) << since;
    if (since < stale - kT) {
      ASSERT_FALSE(r.nearest[k]) << since;
      worst_stale = std::max(worst_stale, std::fabs(r.error[k]));
    } else if (since > stale + kT) {
      ASSERT_TRUE(r.nearest[k]) << since;
    }
    if (since > stale + t_ramp + kT) {
      ASSERT_LE(std::fabs(r.error[k]), crawl_bound(erpm_to_rad_s(40.0))) << since;
    }
  }
  EXPECT_GT(worst_stale, kPi / 3.0 - kTableError - 0.05) << "held 30° past the state's angle, the rotor 30° before it";
}

TEST(IndepVescHall, BlendsTowardsTheObserverAndHandsOverAboveSlErpm) {
  const double offset = 0.0;
  HallAngle h(settings_for(offset));
  const double theta = 0.4, observer = 1.1;  // a rotor at rest in a sector, the observer's angle elsewhere
  for (int k = 0; k < 2000; ++k) h.correct(observer, 0.0, hall_state(theta, offset), kT);  // settled (160 ms)
  const double hall_angle = h.rate_limited_rad();
  for (const double erpm : {0.0, 2400.0, 2500.0, 2750.0, 3000.0, 3400.0, 3500.0, 5000.0, -3000.0, -6000.0}) {
    const double out = h.correct(observer, erpm_to_rad_s(erpm), hall_state(theta, offset), kT);
    ASSERT_NEAR(wrap_pi(h.rate_limited_rad() - hall_angle), 0.0, 1e-12) << "no transition: the Hall angle holds";
    // weight = (3500 − |ERPM|)/(3500 − 2500), within [0, 1].
    const double w = std::clamp((3500.0 - std::fabs(erpm)) / 1000.0, 0.0, 1.0);
    EXPECT_NEAR(h.weight(), w, 1e-12) << erpm;
    EXPECT_NEAR(wrap_pi(out - (observer + w * wrap_pi(hall_angle - observer))), 0.0, 1e-12) << erpm;
    if (std::fabs(erpm) > 3500.0) {
      EXPECT_EQ(out, observer) << "above foc_sl_erpm: the observer's angle itself";
    }
  }
}

TEST(IndepVescHall, InvalidStatesLeaveTheObserversAngle) {
  HallAngle h(settings_for(0.0));
  EXPECT_EQ(h.correct(0.7, 0.0, 0, kT), 0.7);
  EXPECT_EQ(h.correct(0.7, 0.0, 7, kT), 0.7);
  EXPECT_EQ(h.weight(), 0.0);
  EXPECT_NEAR(h.correct(0.7, 0.0, 7, kT, true, -0.2), -0.2, 1e-12) << "the start-up's angle while the sensors are invalid";
}

// The emulated drive in Hall mode: crawling at ~40 ERPM, 1200 ERPM, ~8000 ERPM, zero current.
Case hall_case() {
  Case cs = outrunner_case(8.0);
  cs.firmware.hall = true;
  cs.sensors.hall_offset_deg = 37.0;
  cs.keep_cycle_trace = true;
  const double kt = 1.5 * 7 * 0.004633;  // the configured machine's torque per ampere
  auto b_for = [&](double erpm, double i) { return kt * i / (erpm_to_rad_s(erpm) / 7.0); };
  Segment crawl = segment(SegmentKind::current, 2.7, 8.0);
  crawl.ramp_s = 0.1;
  crawl.viscous_Nm_s = b_for(40.0, 8.0);
  Segment interp = segment(SegmentKind::current, 1.5, 8.0);
  interp.viscous_Nm_s = b_for(1200.0, 8.0);
  Segment fast = segment(SegmentKind::current, 2.0, 12.0);
  fast.viscous_Nm_s = b_for(8000.0, 12.0);
  cs.scenario = {segment(SegmentKind::off, 0.3), crawl, interp, fast, segment(SegmentKind::coast, 1.5)};
  return cs;
}

TEST(IndepVescHall, GeneratorCrawlsOnTheStatesAngleAndRunsOnTheObserverAbove) {
  const Result r = generate(hall_case());
  const std::array<int, 8>& table = r.firmware.hall_table;
  ASSERT_EQ(table, detect_hall_table(37.0 * kDeg));
  const double interp = erpm_to_rad_s(500.0), sl = erpm_to_rad_s(3500.0);
  int crawl = 0, on_table = 0, fast = 0, fast_locked = 0, mid = 0;
  double crawl_worst = 0.0, mid_worst = 0.0;
  for (const CycleRecord& cy : r.cycles) {
    const double eps = wrap_pi(cy.phase_rad - cy.theta_el_rad);
    if (cy.t_s > 0.35 && cy.t_s < 3.0 && std::fabs(cy.omega_el_rad_s) < 0.5 * interp) {
      ++crawl;
      ASSERT_EQ(cy.source, cy.modulating ? AngleSource::hall : AngleSource::off) << cy.t_s;
      ASSERT_LE(std::fabs(eps), crawl_bound(cy.omega_el_rad_s)) << cy.t_s;
      crawl_worst = std::max(crawl_worst, std::fabs(eps));
      if (std::fabs(wrap_pi(cy.phase_rad - table[cy.hall_state] * 2.0 * kPi / 200.0)) < 1e-9) ++on_table;
    }
    if (cy.t_s > 3.7 && cy.t_s < 4.5) {  // the interpolated range, the speed settled
      ++mid;
      ASSERT_EQ(cy.source, AngleSource::hall);
      mid_worst = std::max(mid_worst, std::fabs(eps));
    }
    if (cy.t_s > 5.0 && cy.t_s < 6.5 && std::fabs(cy.omega_el_rad_s) > 1.2 * sl) {
      ++fast;
      ASSERT_EQ(cy.source, AngleSource::observer) << cy.t_s;
      ASSERT_EQ(cy.phase_rad, cy.observer_phase_rad) << "above foc_sl_erpm the observer's angle itself";
      ASSERT_EQ(cy.hall_weight, 0.0);
      fast_locked += std::fabs(eps) < 0.1 ? 1 : 0;
    }
  }
  ASSERT_GT(crawl, 20000);
  EXPECT_GT(crawl_worst, 0.45) << "the frame up to ~30° off the rotor";
  EXPECT_GT(on_table, 0.7 * crawl) << "mostly on a table angle";
  ASSERT_GT(mid, 5000);
  // Interpolated at a nearly constant speed (1200 ERPM ± the ψm offset): the constant-speed bound and a margin for
  // the speed's ripple.
  EXPECT_LT(mid_worst, kMidpointError + 2.0 * erpm_to_rad_s(2000.0) * kT + 0.02);
  ASSERT_GT(fast, 5000);
  EXPECT_GT(fast_locked, 0.95 * fast) << "the observer locked";
  // The truth's rows: crawling windows average the sawtooth over less than a sector: means beyond 0.2 rad.
  int beyond = 0;
  for (const LogRow* row : rows_between(r, 0.5, 3.0)) {
    const RowTruth& t = row->truth;
    EXPECT_EQ(t.angle, "hall");
    EXPECT_EQ(t.hall_fraction, 1.0);
    EXPECT_LE(t.frame_error_max_abs_rad, crawl_bound(0.5 * interp));
    beyond += std::fabs(t.frame_error_mean_rad) > 0.2 ? 1 : 0;
  }
  EXPECT_GE(beyond, 3);
}

TEST(IndepVescHall, SensorlessRunsAreUnchangedByTheHallCode) {
  Case cs = outrunner_case(2.0);
  cs.keep_cycle_trace = true;
  cs.scenario = {segment(SegmentKind::off, 0.2), segment(SegmentKind::current, 1.8, 10.0)};
  const Result r = generate(cs);
  for (const CycleRecord& cy : r.cycles) {
    ASSERT_EQ(cy.hall_weight, 0.0);
    ASSERT_EQ(cy.hall_state, -1);
    ASSERT_NE(cy.source, AngleSource::hall);
  }
  const std::string truth = truth_json(r);
  EXPECT_EQ(truth.find("hall"), std::string::npos) << "no Hall keys in a sensorless truth";
}

// The CLI's Hall ride: crawling rows with frame errors beyond 0.2 rad, none beyond the derived bounds.
TEST(IndepVescHallCli, HallRideTruthShowsTheStatesFrame) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("indep_vesc_hall_cli_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string csv = (dir / "hall.csv").string(), truth_path = (dir / "hall.json").string();
  const std::string command = std::string("\"") + INDEP_VESC_LOG_EXE + "\" --config \"" +
                              testing::source_path("config/vesc-6374-outrunner.yaml") +
                              "\" --hall --seed 4 --duration-s 70 --psi-m-rel 0.2 --r-s-rel -0.15 --out \"" + csv +
                              "\" --truth \"" + truth_path + "\" 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::ifstream in(truth_path);
  const nlohmann::json truth = nlohmann::json::parse(in);
  ASSERT_EQ(truth["vesc"]["foc_sensor_mode"], "hall");
  const auto table = truth["vesc"]["foc_hall_table"].get<std::vector<int>>();
  ASSERT_EQ(table.size(), 8u);
  EXPECT_EQ(table[0], 255);
  EXPECT_EQ(table[7], 255);
  EXPECT_NEAR(truth["true_over_configured"]["psi_m"].get<double>(), 1.2, 1e-9);
  EXPECT_NEAR(truth["true_over_configured"]["r_s"].get<double>(), 0.85, 1e-9);
  for (const auto& seg : truth["scenario"]) ASSERT_NE(seg["kind"], "flux_measurement");
  std::ifstream log(csv);
  std::size_t lines = 0;
  for (std::string line; std::getline(log, line);) ++lines;
  ASSERT_EQ(lines, truth["rows"].size() + 1);

  const double interp = erpm_to_rad_s(500.0), sl = erpm_to_rad_s(3500.0);
  int crawl = 0, beyond = 0, stale = 0, interpolated = 0, observer = 0, observer_locked = 0, zero_current = 0;
  double crawl_worst = 0.0, hall_worst = 0.0;
  double previous_interpolated = 1.0;
  for (const auto& row : truth["rows"]) {
    const double interpolated_now = row["hall_interpolated_fraction"].get<double>();
    const double interpolated_before = previous_interpolated;
    previous_interpolated = interpolated_now;
    if (row["cycles"].get<int>() == 0 || row["t_window_start_s"].get<double>() < 0.05) continue;
    const double w0 = std::fabs(row["omega_el_start_rad_s"].get<double>());
    const double w1 = std::fabs(row["omega_el_end_rad_s"].get<double>());
    const double wm = std::fabs(row["omega_el_mean_rad_s"].get<double>());
    const double mean = row["frame_error_mean_rad"].get<double>(), max_abs = row["frame_error_max_abs_rad"].get<double>();
    const double hall = row["hall_fraction"].get<double>();
    const bool modulating = row["bridge"] == "modulating";
    if (hall == 1.0) {
      // Anywhere on the Hall angle: the frame within its state's ±30° and the rotor within its sector's.
      EXPECT_LE(max_abs, kPi / 3.0 + kMidpointError) << row["t_s"];
      hall_worst = std::max(hall_worst, max_abs);
    }
    // Crawling on the nearest state's angle (in this window and the one before, so that no rate-limited return from
    // an interpolated angle is left): the crawl bound. Interpolating while crawling happens only at the stale speed
    // of a reversal after a fast stop (AReversalAfterAFastStop…), within the all-Hall bound above.
    if (hall == 1.0 && std::max({w0, w1, wm}) < 0.5 * interp && (interpolated_now > 0.0 || interpolated_before > 0.0)) {
      ++stale;
    }
    if (hall == 1.0 && std::max({w0, w1, wm}) < 0.5 * interp && interpolated_now == 0.0 && interpolated_before == 0.0) {
      ++crawl;
      EXPECT_LE(max_abs, crawl_bound(0.5 * interp)) << "crawling at " << row["t_s"];
      crawl_worst = std::max(crawl_worst, max_abs);
      beyond += std::fabs(mean) > 0.2 ? 1 : 0;
    }
    if (hall == 1.0 && modulating && std::min(w0, w1) > 1.2 * interp && std::max(w0, w1) < 0.8 * erpm_to_rad_s(2500.0)) {
      ++interpolated;
    }
    if (hall == 0.0 && modulating && std::min(w0, w1) > 1.2 * sl) {
      ++observer;
      observer_locked += row["angle_locked"].get<bool>() ? 1 : 0;
    }
    if (modulating && row["segment"] == "coast") ++zero_current;
  }
  EXPECT_GT(crawl, 50);
  EXPECT_GE(beyond, 10) << "crawling rows whose mean frame error exceeds 0.2 rad";
  EXPECT_GT(crawl_worst, 0.45);
  EXPECT_GT(interpolated, 20);
  EXPECT_GT(observer, 20);
  EXPECT_GT(observer_locked, 0.9 * observer);
  EXPECT_GT(zero_current, 20);
  EXPECT_LT(stale, crawl / 5);
  RecordProperty("crawl_rows", crawl);
  RecordProperty("crawl_rows_after_interpolation", stale);
  RecordProperty("crawl_rows_beyond_0_2_rad", beyond);
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace
}  // namespace indep::vesc
