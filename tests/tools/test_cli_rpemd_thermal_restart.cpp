// The real rpemd restarted on a hot machine (docs/thermal.md, "A restart"): on its simulated drive with a thermal
// network it keeps the fusion's state in its state file; killed (no last write) and restarted with that state made
// hot and 30 s old, it says it resumes, and what it writes next stands where core::across_unknown_load puts the
// saved state after the gap — not at the coolant, where a start from nothing puts it — in its state file and on its
// status line (~6 s, real time).
#include <gtest/gtest.h>

#include <csignal>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "rpem/core/thermal_resume.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/state_file.hpp"
#include "support/child_process.hpp"
#include "support/process.hpp"
#include "support/temp_file.hpp"

namespace {

using rpem::test::TempFile;

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

/// Runs rpemd for `seconds`, then ends it with `sig`; its log.
std::string run_rpemd(const std::string& config, double seconds, int sig) {
  const TempFile log("rpemd_restart.log");
  rpem::test::ChildProcess rpemd({rpem::test::binary_dir() + "/daemon/rpemd", "--config", config}, log.path());
  EXPECT_GT(rpemd.pid(), 0);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  rpemd.signal(sig);
  (void)rpemd.wait();
  return rpem::test::read_file(log.path());
}

TEST(RpemdThermalRestart, AKilledRpemdRestartsItsFusionWhereTheSavedStateStandsNow) {
  const TempFile state("rpemd_restart_state.json");
  const std::string machine = rpem::test::read_file(rpem::test::source_dir() + "/config/paper-ipmsm.yaml");
  const TempFile config("rpemd_restart.yaml", machine +
                                                  "thermal:\n"
                                                  "  nodes:\n"
                                                  "    - {name: winding, capacitance_J_per_K: 3000, to_coolant_W_per_K: 2}\n"
                                                  "    - {name: magnet, capacitance_J_per_K: 7000, to_coolant_W_per_K: 4}\n"
                                                  "  conductances: [{from: winding, to: magnet, W_per_K: 12}]\n"
                                                  "  coolant_C: 35\n"
                                                  "daemon:\n"
                                                  "  lcm: {url: \"memq://\"}\n"
                                                  "  state: {file: " +
                                                  state.path() + ", write_interval_s: 1}\n");
  // A crash: SIGKILL, so the file is the last periodic write. Started from nothing, without a winding sensor, the
  // fusion's soaked start is an assumption rpemd says.
  const std::string first = run_rpemd(config.path(), 3.0, SIGKILL);
  EXPECT_NE(first.find("rpemd: note: the thermal network starts soaked, every node at the coolant, an assumption"),
            std::string::npos)
      << first;
  nlohmann::json saved = read_json(state.path());
  ASSERT_TRUE(saved.contains("thermal")) << saved.dump();
  ASSERT_EQ(saved["thermal"]["nodes"], 2);
  EXPECT_NEAR(saved["thermal"]["t_C"][1].get<double>(), 35.0, 1.0);  // a few seconds from a soaked start

  // The machine hot when it was written, 30 s ago.
  const std::int64_t at_s = std::time(nullptr) - 30;
  saved["thermal"]["t_C"] = {95.0, 88.0};
  saved["thermal"]["at_unix_s"] = at_s;
  saved["written_unix_s"] = at_s;
  std::ofstream(state.path()) << saved.dump();
  const rpem::daemon::DaemonConfig c = rpem::daemon::load_daemon_config(config.path());
  const rpem::core::EstimatorSettings& est = c.live.machine.estimator;
  const rpem::daemon::LoadedState hot = rpem::daemon::load_state_file(
      state.path(), c.fixed.state.max_age_s, est.psi_m_min_Wb, est.psi_m_max_Wb, est.r_s_min_Ohm, est.r_s_max_Ohm);
  ASSERT_EQ(hot.status, rpem::daemon::StateFileStatus::kLoaded) << hot.message;
  const rpem::core::ThermalSnapshot expected = rpem::core::across_unknown_load(
      c.live.thermal.filter, hot.estimates.thermal.state, 30.0, c.live.thermal.observer.period_s);

  const std::string log = run_rpemd(config.path(), 3.0, SIGTERM);
  EXPECT_NE(log.find("rpemd: the thermal network resumes from the state file (magnet 88.0 C, winding 95.0 C 3"),
            std::string::npos)
      << log;
  EXPECT_EQ(log.find("starts soaked"), std::string::npos) << log;  // resumed: nothing assumed
  const nlohmann::json after = read_json(state.path());
  ASSERT_TRUE(after.contains("thermal")) << after.dump();
  EXPECT_GT(after["thermal"]["at_unix_s"].get<std::int64_t>(), at_s);  // the fusion's own state, written at the end
  // Three seconds of the simulated drive against time constants of minutes: within 2 K of where the gap left the
  // magnet, 45 K above the coolant a start from nothing reports.
  const double magnet_C = after["thermal"]["t_C"][1];
  EXPECT_NEAR(magnet_C, expected.t_C[1], 2.0);
  EXPECT_GT(magnet_C, 35.0 + 45.0);
  // Its status line says so too (docs/rpemd.md, "The status line"): the newest fused magnet where the gap left it.
  const std::string fused = "fused: T_magnet ";
  const std::size_t at = log.rfind(fused);
  ASSERT_NE(at, std::string::npos) << log;
  EXPECT_NEAR(std::stod(log.substr(at + fused.size())), expected.t_C[1], 2.0) << log;
}

}  // namespace
