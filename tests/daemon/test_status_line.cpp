// rpemd's status line (docs/rpemd.md, "The status line"), whole lines against the format the docs show: the
// parameters with their marks and derived temperatures; with a thermal network the fused temperatures, each
// observed or predicted since its last observation; the simulated drive's truth with its temperatures; a VESC
// source's poll counters; a frozen estimator. The VM suites' checkers read its state and psi_m (split()[1],
// `psi_m=… Wb`): they stay where they were.
#include "rpem/daemon/status_line.hpp"

#include <gtest/gtest.h>

#include "rpem/mirror/diagnostics_t.hpp"

namespace rpem::daemon {
namespace {

/// The docs' second example: ψm adapting and valid, R_s held 24 s and no longer valid.
EstimateReport docs_example() {
  EstimateReport r;
  r.state = static_cast<std::int8_t>(DaemonState::kRunning);
  r.speed_pu = 0.3;
  r.psi_m_Wb = 1.0973;
  r.psi_m_adapting = true;
  r.psi_m_valid = true;
  r.t_magnet_C = 51.2;
  r.r_s_Ohm = 2.4851;
  r.r_s_age_s = 24.2;
  r.r_s_valid = false;
  r.t_winding_C = 46.6;
  return r;
}

constexpr const char* kHead =
    "rpemd running  n=+0.300 pu  psi_m=1.0973 Wb* (T_magnet  51.2 C)  r_s=2.4851 Ohm held 24 s? (T_winding  46.6 C)";

TEST(StatusLine, WithoutANetworkItIsTheParametersAndTheirDerivedTemperatures) {
  EXPECT_EQ(status_line(docs_example(), SourceReport{}), kHead);
  EstimateReport initial = docs_example();
  initial.state = static_cast<std::int8_t>(DaemonState::kStale);
  initial.psi_m_adapting = false;
  initial.psi_m_age_s = -1.0;  // never adapted: the initial value, no mark but validity
  initial.frozen = true;
  EXPECT_EQ(status_line(initial, SourceReport{}),
            "rpemd STALE    n=+0.300 pu  psi_m=1.0973 Wb (T_magnet  51.2 C)  r_s=2.4851 Ohm held 24 s? (T_winding  46.6 C)"
            "  FROZEN");
}

TEST(StatusLine, WithANetworkItShowsBothFusedTemperaturesAndHowEachStands) {
  EstimateReport r = docs_example();
  r.thermal_active = true;
  r.t_magnet_fused_C = 61.24, r.t_magnet_fused_sd_C = 3.06, r.t_magnet_observed_age_s = 0.0;
  r.t_magnet_source = mirror::estimate_t::SOURCE_OBSERVED;
  r.t_winding_fused_C = 75.04, r.t_winding_fused_sd_C = 0.81, r.t_winding_observed_age_s = 40.4;
  r.t_winding_source = mirror::estimate_t::SOURCE_PREDICTED;
  EXPECT_EQ(status_line(r, SourceReport{}), std::string(kHead) +
                                                "  fused: T_magnet 61.2 C sd 3.1 K observed, T_winding 75.0 C sd 0.8 K "
                                                "predicted, observed 40 s ago");
  r.t_winding_observed_age_s = -1.0;  // never observed since the start
  EXPECT_NE(status_line(r, SourceReport{}).find("T_winding 75.0 C sd 0.8 K predicted, never observed"), std::string::npos);
  r.thermal_active = false;  // configured but not yet stepped, or none: no fused part
  EXPECT_EQ(status_line(r, SourceReport{}), kHead);
}

TEST(StatusLine, TheSimulatedDrivesTruthCarriesItsTemperaturesAndAVescItsPolls) {
  SourceReport sim;
  sim.has_truth = true;
  sim.truth_psi_m_Wb = 1.0968, sim.truth_r_s_Ohm = 2.5123;
  sim.truth_t_magnet_C = 50.06, sim.truth_t_winding_C = 49.74;
  EXPECT_EQ(status_line(docs_example(), sim),
            std::string(kHead) + "  [sim truth 1.0968 Wb 2.5123 Ohm, T_magnet 50.1 C T_winding 49.7 C]");
  SourceReport vesc;
  using D = rpem::diagnostics_t;
  vesc.rows.set(&D::vesc_polls, 120);
  vesc.rows.set(&D::vesc_replies, 118);
  vesc.rows.set(&D::vesc_timeouts, 2);
  vesc.rows.set(&D::vesc_late_replies, 1);
  vesc.rows.set(&D::vesc_unrequested_replies, 0);
  vesc.rows.set(&D::vesc_stolen_reads, 3);
  EXPECT_EQ(status_line(docs_example(), vesc),
            std::string(kHead) + "  [vesc polls 120 replies 118 timeouts 2 late 1 unrequested 0 stolen_reads 3]");
}

}  // namespace
}  // namespace rpem::daemon
