// The VESC source's counted speeds (daemon/count_delay.hpp): windows held back until the reads after them have
// come, none lost or reordered, each window's speed counted over the reads around it — checked against the
// count's own bound on a constant speed, and end to end on the emulated VESC in Hall mode at a crawl
// (scenarios/vesc-tool-hall.yaml): its firmware's replies (can/vesc_firmware) through the poller at 200 Hz, the
// windows' counted speeds against the plant's true mean speed over each window, beside the PLL's rebuilt one.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "rpem/can/vesc_firmware.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/daemon/count_delay.hpp"
#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/vesc_source.hpp"
#include "rpem/sim/vesc_on_demand.hpp"
#include "support/temp_file.hpp"

namespace rpem::daemon {
namespace {

namespace vesc = can::vesc;
constexpr double kStep = vesc::kTachometerStepRad;
constexpr std::int64_t kMillisecondNs = 1'000'000;

core::AveragedSample window(std::int64_t start_ns, std::int64_t end_ns) {
  core::AveragedSample w;
  w.t_start_ns = start_ns;
  w.t_ns = end_ns;
  w.omega_el_rad_s = 1.0;
  return w;
}

// GIVEN reads every 5 ms of a count at 20 rad/s and a window ending at each WHEN released as time passes THEN
// each leaves once the horizon after it has passed, in order, with its counted speed within one step over its run
// (≈ 0.5 s: 2.1 rad/s) of 20 rad/s; a window at the start has only the reads there are.
TEST(CountDelay, HoldsEachWindowForItsHorizonAndCountsItsSpeed) {
  CountDelay delay(kStep, 0.25);
  std::vector<core::AveragedSample> out;
  std::vector<core::CountRead> reads;
  core::AveragedSample due;
  for (int k = 0; k <= 400; ++k) {
    const std::int64_t t = k * 5 * kMillisecondNs;
    reads.push_back({t, kStep * std::floor(0.3 + 20.0 * core::to_seconds(t) / kStep)});
    delay.add_read(reads.back());
    if (k > 0) delay.add_window(window(t - 5 * kMillisecondNs, t));
    while (delay.release(t, due)) out.push_back(due);
  }
  ASSERT_EQ(out.size(), 350U);  // windows ending at 5 … 1 750 ms: 1 750 + 250 ≤ 2 000
  for (std::size_t j = 0; j < out.size(); ++j) {
    EXPECT_EQ(out[j].t_ns, static_cast<std::int64_t>(j + 1) * 5 * kMillisecondNs);
    EXPECT_DOUBLE_EQ(out[j].omega_el_rad_s, 1.0);  // the reported speed is left as it was
    if (j >= 50) {
      EXPECT_NEAR(out[j].omega_counted_el_rad_s, 20.0, kStep / 0.49) << j;
    }
    // What rpem estimate counts over the same reads (io's reader takes the same function over all of them).
    EXPECT_EQ(out[j].omega_counted_el_rad_s, core::grown_count_speed_rad_s(reads, j, j + 1, kStep, 250 * kMillisecondNs))
        << j;
  }
  EXPECT_EQ(delay.held(), 50U);
  while (delay.release(2'001 * kMillisecondNs + 250 * kMillisecondNs, due)) out.push_back(due);
  EXPECT_EQ(out.size(), 400U);  // the source keeps calling release() while the drive is silent: none is lost
}

// A full ring releases its oldest at once (its run shorter after it); a window whose reads have been overwritten
// carries no count; no window is lost either way.
TEST(CountDelay, AFullRingReleasesItsOldestEarlyAndLosesNone) {
  CountDelay delay(kStep, 10.0);  // a horizon no ring holds at 1 kHz
  std::vector<core::AveragedSample> out;
  core::AveragedSample due;
  const std::size_t n = CountDelay::kReads + 10;
  for (std::size_t k = 0; k < n; ++k) {
    const auto t = static_cast<std::int64_t>(k) * kMillisecondNs;
    delay.add_read({t, 0.0});
    if (k == 0) continue;
    while (delay.full() && delay.release(t, due)) out.push_back(due);
    delay.add_window(window(t - kMillisecondNs, t));
    if (!delay.full()) {
      EXPECT_FALSE(delay.release(t, due));  // neither due nor full
    }
  }
  EXPECT_EQ(out.size() + delay.held(), n - 1);
  EXPECT_EQ(delay.held(), CountDelay::kWindows);
  ASSERT_FALSE(out.empty());
  EXPECT_DOUBLE_EQ(out.front().omega_counted_el_rad_s, 0.0);
  // Reads with no window (replies whose windows were dropped) overwrite the oldest: the oldest held window, which
  // ends at read n − kWindows, loses the read before it, where it starts.
  for (std::size_t k = n; k < n + CountDelay::kReads - CountDelay::kWindows; ++k) {
    delay.add_read({static_cast<std::int64_t>(k) * kMillisecondNs, 0.0});
  }
  ASSERT_TRUE(delay.release(std::int64_t{1} << 60, due));
  EXPECT_EQ(due.t_ns, static_cast<std::int64_t>(n - CountDelay::kWindows) * kMillisecondNs);
  EXPECT_TRUE(std::isnan(due.omega_counted_el_rad_s)) << due.omega_counted_el_rad_s;
  ASSERT_TRUE(delay.release(std::int64_t{1} << 60, due));  // the next one still has its start
  EXPECT_DOUBLE_EQ(due.omega_counted_el_rad_s, 0.0);
}

/// The emulated VESC of scenarios/vesc-tool-hall.yaml (Hall sensors, crawling) polled at 200 Hz through the
/// poller with the counting mask and the delay, its replies the firmware's bytes; each window released with the
/// plant's true mean speed over it (the true angle unwrapped between polls: below π per 5 ms at a crawl).
struct HallRun {
  std::vector<core::AveragedSample> windows;
  std::vector<double> true_rad_s;  ///< NaN where the window is not at a crawl (the angle's unwrap would fail)
  std::uint64_t samples = 0;
};

HallRun run_hall_crawl(double duration_s) {
  sim::Scenario scenario = sim::load_scenario(test::source_dir() + "/scenarios/vesc-tool-hall.yaml");
  scenario.duration_s = duration_s;
  sim::OnDemandVesc::Settings settings;
  settings.motor.controller_id = 17;
  settings.status = {{{0.0, 0}, {0.0, 0}}};
  sim::OnDemandVesc drive(scenario, settings);
  VescSource::Options o;
  o.controller_id = 17;
  o.host_id = 125;
  o.count_horizon_s = core::kCountRunSideMaxS;
  VescPoller poller(poller_config(o));
  CountDelay delay(kStep, o.count_horizon_s);
  HallRun run;
  std::vector<std::pair<std::int64_t, double>> true_angle;  // at each poll: time, unwrapped true angle
  double theta = 0.0, previous_wrapped = 0.0;
  auto ignore = [](const vesc::Status&) {};
  std::array<std::uint8_t, vesc::kMaxValuesPayload> payload{};
  std::array<can::CanFrame, 16> frames{};
  core::AveragedSample sample, due;
  const auto release = [&](std::int64_t now) {
    while (delay.release(now, due)) run.windows.push_back(due);
  };
  for (std::int64_t t = 10 * kMillisecondNs;; t += 5 * kMillisecondNs) {
    poller.polled(t, true);
    const auto read = drive.poll(t, ignore);
    if (!read) break;
    const double wrapped = drive.motor().truth().theta_el_rad;
    theta += true_angle.empty() ? wrapped : core::wrap_angle(wrapped - previous_wrapped);
    previous_wrapped = wrapped;
    true_angle.emplace_back(t, theta);
    const std::size_t len = vesc::encode_values(read->values, poller_config(o).mask, payload);
    const std::size_t n = vesc::buffer_frames(125, 17, 1, std::span(payload).first(len), frames);
    const std::int64_t rx = t + 200'000;  // the reply's first frame, 0.2 ms after the poll
    for (std::size_t f = 0; f < n; ++f) {
      const std::uint64_t reads = poller.reads();
      const bool sampled = poller.on_frame(frames[f], rx + static_cast<std::int64_t>(f) * 20'000, sample);
      if (poller.reads() != reads) delay.add_read(poller.last_read());
      if (sampled) {
        ++run.samples;
        delay.add_window(sample);
      }
    }
    release(rx);
  }
  release(std::int64_t{1} << 62);
  // The true mean speed over each window: the poll times are the drive's read times, the window's ends the replies'.
  std::size_t j = 0;
  for (const core::AveragedSample& w : run.windows) {
    const std::int64_t start = w.t_start_ns - 200'000, end = w.t_ns - 200'000;
    while (j + 1 < true_angle.size() && true_angle[j].first < start) ++j;
    std::size_t k = j;
    while (k + 1 < true_angle.size() && true_angle[k].first < end) ++k;
    const double mean = (true_angle[k].second - true_angle[j].second) / core::to_seconds(end - start);
    run.true_rad_s.push_back(
        true_angle[j].first == start && true_angle[k].first == end && std::abs(mean) < 52.0 ? mean : std::nan(""));
  }
  return run;
}

// GIVEN the emulated Hall VESC crawling at 5, 15 and 30 rpm (35–210 erpm: each state's angle held) WHEN polled at
// 200 Hz THEN every window is released, in order, and at a crawl its counted speed is within the count's bound over
// a full run (2 steps over 0.5 s: 4.2 rad/s) of the plant's mean over it in RMS, where the PLL's rebuilt speed —
// tracking a staircase — is off by several times that.
TEST(CountDelay, AHallDrivesCrawlIsCountedWhereItsPllSpeedIsNot) {
  const HallRun run = run_hall_crawl(26.0);
  ASSERT_EQ(run.windows.size(), run.samples);
  double counted_sq = 0.0, pll_sq = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < run.windows.size(); ++k) {
    if (k > 0) {
      ASSERT_GT(run.windows[k].t_ns, run.windows[k - 1].t_ns);
    }
    if (std::isnan(run.true_rad_s[k]) || std::abs(run.true_rad_s[k]) < 1.0) continue;
    counted_sq += std::pow(run.windows[k].omega_counted_el_rad_s - run.true_rad_s[k], 2);
    pll_sq += std::pow(run.windows[k].omega_el_rad_s - run.true_rad_s[k], 2);
    ++n;
  }
  ASSERT_GT(n, 2000);  // 18 s of crawl at 200 Hz
  const double counted_rms = std::sqrt(counted_sq / n), pll_rms = std::sqrt(pll_sq / n);
  RecordProperty("counted_rms_rad_s", std::to_string(counted_rms));
  std::printf("[ crawl    ] %d windows: counted RMS %.2f rad/s, the PLL's %.2f rad/s\n", n, counted_rms, pll_rms);
  EXPECT_LT(counted_rms, 2.0 * kStep / 0.5);
  EXPECT_GT(pll_rms, 3.0 * counted_rms);
}

// rpemd counts where the machine's angle is a Hall drive's staircase: a VESC source beside a configuration with
// `angle_source: hall` asks for the tachometer and holds its windows for the horizon; the stock (sensorless)
// one neither — its polls and windows as before.
TEST(CountDelay, TheVescSourceCountsWhereTheMachineIsAHallDrive) {
  std::ifstream in(test::source_dir() + "/config/vesc-6374-outrunner.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string hall = std::regex_replace(text.str(), std::regex("angle_source: sensorless"), "angle_source: hall");
  ASSERT_NE(hall, text.str());
  const test::TempFile machine("hall-machine.yaml", hall);
  const test::TempFile config("rpemd-hall.yaml",
                              "daemon:\n  machine_config: " + std::filesystem::path(machine.path()).filename().string() +
                                  "\n  source:\n    type: vesc\n    vesc: {interface: can0, "
                                  "controller_id: 17}\n");
  const auto counting = std::get<VescSource::Options>(load_daemon_config(config.path()).fixed.source);
  EXPECT_DOUBLE_EQ(counting.count_horizon_s, core::kCountRunSideMaxS);
  EXPECT_EQ(poller_config(counting).mask, vesc::kCountingMask);
  const auto stock =
      std::get<VescSource::Options>(load_daemon_config(test::source_dir() + "/config/rpemd-vesc.yaml").fixed.source);
  EXPECT_DOUBLE_EQ(stock.count_horizon_s, 0.0);
  EXPECT_EQ(poller_config(stock).mask, vesc::kEstimatorMask);
}

}  // namespace
}  // namespace rpem::daemon
