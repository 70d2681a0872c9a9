// The thermal fields of RPEM_ESTIMATE (docs/thermal.md, "In rpemd"): filled from the loop's fusion, NaN/0/−1
// without a network, and named as `rpem estimate --thermal` names its columns.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "rpem/daemon/loop_thread.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/io/estimate_log.hpp"
#include "rpem/schema/text.hpp"
#include "support/loop_queues.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

/// Runs `seconds` of the model's phase samples at 8 kHz (n = 0.4 pu: ψm adapts) through a loop; the last estimate.
EstimateReport run_loop(const DaemonConfig& config, int seconds) {
  auto [input, commands, output, ends] = test::loop_queues(4096, 16, 1 << 12);
  LoopThread loop(config, std::move(ends));
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = test::paper_base().omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
  const core::PerUnitBase base = test::paper_base();
  std::int64_t t_ns = 0, now = 1'000'000'000;
  EstimateReport last;
  Report r;
  for (int period = 0; period < seconds * 1000; ++period) {
    for (int s = 0; s < 8; ++s) (void)input.push(gen.next_si(base, t_ns));
    now += 1'000'000;
    loop.process(now);
    while (output.pop(r)) {
      if (const auto* e = std::get_if<EstimateReport>(&r)) last = *e;
    }
  }
  return last;
}

TEST(LoopThermal, WithoutANetworkTheFieldsSayNone) {
  const EstimateReport e = run_loop(builtin_daemon_config(), 2);
  EXPECT_FALSE(e.thermal_active);
  EXPECT_TRUE(std::isnan(e.t_magnet_fused_C));
  EXPECT_TRUE(std::isnan(e.t_winding_fused_sd_C));
  EXPECT_EQ(e.t_magnet_source, 0);
  EXPECT_EQ(e.t_winding_source, 0);
  EXPECT_EQ(e.t_magnet_observed_age_s, -1.0);
}

TEST(LoopThermal, WithANetworkTheFusedTemperaturesAreReported) {
  DaemonConfig config = builtin_daemon_config();
  config.live.thermal = test::paper_thermal_fusion();
  config.live.thermal.coolant_C = 40.0;
  config.live.thermal_active = true;
  const EstimateReport e = run_loop(config, 10);
  ASSERT_TRUE(e.thermal_active);
  // Ten seconds against time constants of minutes, from a soaked machine at the coolant: near 40 °C, and the
  // magnet observed through ψ̂m (the model's ψm is the law's value at 20 °C: the observations pull it down).
  EXPECT_TRUE(std::isfinite(e.t_magnet_fused_C));
  EXPECT_GT(e.t_magnet_fused_sd_C, 0.0);
  EXPECT_LT(e.t_magnet_fused_sd_C, test::paper_thermal_fusion().initial_sigma_K);
  EXPECT_GT(e.t_winding_fused_sd_C, 0.0);
  EXPECT_TRUE(e.t_magnet_source == 1 || e.t_magnet_source == 2);
  EXPECT_TRUE(e.t_winding_source == 1 || e.t_winding_source == 2);
  EXPECT_GE(e.t_magnet_observed_age_s, 0.0);  // observed at least once
  EXPECT_LT(e.t_magnet_observed_age_s, 10.0);
}

TEST(LoopThermal, TheEstimateCsvNamesTheColumnsAsRpemListensCsv) {
  const std::string listen = schema::csv_header<rpem::estimate_t>();
  const test::TempFile f("est.csv");
  { io::EstimateLogWriter w(f.path(), {"winding", "magnet"}); }
  const std::string estimate = test::read_file(f.path());
  auto columns = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream s(line.substr(0, line.find('\n')));
    for (std::string c; std::getline(s, c, ',');) out.push_back(c);
    return out;
  };
  const std::vector<std::string> l = columns(listen), est = columns(estimate);
  for (const char* node : {"magnet", "winding"}) {
    const std::string n(node);
    for (const std::string& c :
         {"t_" + n + "_fused_C", "t_" + n + "_fused_sd_C", "t_" + n + "_source", "t_" + n + "_observed_age_s"}) {
      SCOPED_TRACE(c);
      EXPECT_NE(std::find(l.begin(), l.end(), c), l.end());
      EXPECT_NE(std::find(est.begin(), est.end(), c), est.end());
    }
  }
}

}  // namespace
}  // namespace rpem::daemon
