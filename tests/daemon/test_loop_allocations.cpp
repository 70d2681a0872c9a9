// The loop's period work allocates nothing: 20 s of samples at 8 kHz, every kind of command (a reload
// carries the whole live configuration), stale periods, all report kinds with their diagnostics rows,
// validity and age tracking — counted by replacing the global allocation functions.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <variant>

#include "rpem/can/vesc.hpp"
#include "rpem/command_t.hpp"
#include "rpem/daemon/command_gate.hpp"
#include "rpem/daemon/count_delay.hpp"
#include "rpem/daemon/loop_thread.hpp"
#include "rpem/daemon/speed_error_delay.hpp"
#include "support/averaged_data.hpp"
#include "support/loop_queues.hpp"
#include "support/model_data.hpp"
#include "support/paper_machine.hpp"
#include "support/paper_thermal.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace rpem::daemon {
namespace {

/// What the phase path's run saw of the thermal fields.
struct ThermalSeen {
  int active = 0, observed = 0;
};

/// 20 s of phase samples at 8 kHz through the loop with every kind of command; the allocations counted.
long phase_path_allocations(const DaemonConfig& config, ThermalSeen& seen) {
  auto [input, commands, output, ends] = test::loop_queues(4096, 16, 1 << 16);
  LoopThread loop(config, std::move(ends));
  loop.seed(SeedValue{1.1, 4.0}, SeedValue{2.3, 4.0}, 1'000'000'000);
  test::ModelDataGenerator gen;
  gen.plant = test::paper_machine_pu();
  gen.omega_n_rad_s = test::paper_base().omega_el_rad_s;
  gen.n_pu = 0.4;
  gen.i_ref_pu = core::mtpa_reference(gen.plant, 0.4);
  std::vector<core::DriveSample> samples;
  std::int64_t t_ns = 0;
  const core::PerUnitBase base = test::paper_base();
  for (int k = 0; k < 160'000; ++k) samples.push_back(gen.next_si(base, t_ns));
  std::vector<Command> cmds(5);
  cmds[0].kind = Command::Kind::kFreeze;
  cmds[1].kind = Command::Kind::kUnfreeze;
  cmds[2].kind = Command::Kind::kSetValues;
  cmds[2].psi_m_Wb = 1.1;
  cmds[2].r_s_Ohm = 2.3;
  cmds[3].kind = Command::Kind::kReconfigure;
  cmds[3].live = config.live;
  cmds[3].live.validity.max_hold_s = 1.0;
  cmds[4].kind = Command::Kind::kReset;
  for (std::size_t k = 0; k < cmds.size(); ++k)
    cmds[k].seq = cmds[k].kind == Command::Kind::kReconfigure ? 0 : static_cast<std::int64_t>(k + 1);

  const long before = g_allocations.load();
  std::int64_t now = 1'000'000'000;
  std::size_t next = 0;
  Report drain;
  for (int period = 0; period < 20'000; ++period) {
    if (period % 4000 == 100) (void)commands.push(cmds[static_cast<std::size_t>(period / 4000)]);
    const bool stall = period >= 9000 && period < 9500;  // a stale half-second
    for (int s = 0; s < 8 && !stall && next < samples.size(); ++s) (void)input.push(samples[next++]);
    now += 1'000'000;
    loop.process(now);
    if (period % 1000 == 0) {
      const long counted = g_allocations.load();  // the test's own inspection is not the loop's work
      while (output.pop(drain)) {
        if (const auto* e = std::get_if<EstimateReport>(&drain)) {
          seen.active += e->thermal_active;
          seen.observed += e->t_magnet_source == mirror::estimate_t::SOURCE_OBSERVED ||
                           e->t_winding_source == mirror::estimate_t::SOURCE_OBSERVED;
        }
      }
      g_allocations.store(counted);
    }
  }
  return g_allocations.load() - before;
}

TEST(LoopAllocations, NoneInTheLoopsPeriodWork) {
  ThermalSeen seen;
  EXPECT_EQ(phase_path_allocations(builtin_daemon_config(), seen), 0);
  EXPECT_EQ(seen.active, 0);  // no thermal section: no fusion
}

// The same with the thermal network's filter stepping beside the estimator on every sample (issue 24):
// observations, filter steps every 10 ms, a reload carrying the network, a reset.
TEST(LoopAllocations, NoneWithTheThermalFilter) {
  DaemonConfig config = builtin_daemon_config();
  config.live.thermal = test::paper_thermal_fusion();
  config.live.thermal_active = true;
  ThermalSeen seen;
  EXPECT_EQ(phase_path_allocations(config, seen), 0);
  EXPECT_GT(seen.active, 100);  // 10 Hz estimates over 20 s, the first after the filter's first step
  EXPECT_GT(seen.observed, 0);  // corrected by ψ̂m or r̂s at least once at a report
}

// The averaged path (source: vesc, rotor-frame signal maps): 20 s of windows at 1 kHz with jitter, a
// silence, commands; nothing allocated either.
TEST(LoopAllocations, NoneOnTheAveragedPath) {
  DaemonConfig config = builtin_daemon_config();
  config.fixed.source = VescSource::Options{};
  auto [input, commands, output, ends] = test::loop_queues(4096, 16, 1 << 16);
  LoopThread loop(config, std::move(ends));
  test::AveragedDataGenerator gen;
  gen.base = test::paper_base();
  gen.plant = test::paper_machine_pu();
  gen.rate_Hz = 1000.0;
  const core::Vec2 i = core::mtpa_reference(gen.plant, 0.4);
  gen.n_pu = [](double) { return 0.5; };
  gen.i_pu = [i](double) { return i; };
  std::vector<core::AveragedSample> samples;
  while (gen.t_s < 20.0) samples.push_back(gen.next());
  Command freeze, reset, reload;
  freeze.kind = Command::Kind::kFreeze;
  reset.kind = Command::Kind::kReset;
  reload.kind = Command::Kind::kReconfigure;
  reload.live = config.live;

  const long before = g_allocations.load();
  std::int64_t now = 0;
  std::size_t next = 0;
  Report drain;
  for (int period = 0; period < 20'000; ++period) {
    if (period == 3000) (void)commands.push(freeze);
    if (period == 6000) (void)commands.push(reload);
    if (period == 12000) (void)commands.push(reset);
    now += 1'000'000;
    const bool silent = period >= 9000 && period < 9500;
    while (next < samples.size() && samples[next].t_ns <= now) {
      if (!silent) (void)input.push(samples[next]);
      ++next;
    }
    loop.process(now);
    if (period % 1000 == 0) {
      while (output.pop(drain)) {
      }
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(next, 19'000u);
}

// The VESC source's count delay (a Hall drive's windows held for their counted speeds; its thread's per-reply
// work) allocates nothing once made: 20 s of replies at 2 kHz, the ring full at times (a 0.6 s horizon).
TEST(LoopAllocations, NoneInTheVescSourcesCountDelay) {
  const auto delay = std::make_unique<CountDelay>(can::vesc::kTachometerStepRad, 0.6);
  const long before = g_allocations.load();
  core::AveragedSample window, due;
  std::size_t released = 0;
  for (std::int64_t k = 0; k < 40'000; ++k) {
    const std::int64_t t = k * 500'000;
    delay->add_read({t, can::vesc::kTachometerStepRad * static_cast<double>(k / 100)});
    if (k == 0) continue;
    window.t_start_ns = t - 500'000;
    window.t_ns = t;
    while (delay->full() && delay->release(t, due)) ++released;
    delay->add_window(window);
    while (delay->release(t, due)) ++released;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(released + delay->held(), 39'999U);
}

// The VESC source's speed-error delay (each window held one reply, judged by the changes at both its ends and the
// latest changes' noise) allocates nothing either: 20 s of replies at 2 kHz.
TEST(LoopAllocations, NoneInTheVescSourcesSpeedErrorDelay) {
  SpeedErrorDelay delay(core::PllGains{can::vesc::kDefaultPllKp, can::vesc::kDefaultPllKi});
  const long before = g_allocations.load();
  core::AveragedSample window, due;
  std::size_t released = 0;
  for (std::int64_t k = 1; k < 40'000; ++k) {
    const std::int64_t t = k * 500'000;
    if (delay.on_read(k % 7 == 0 ? 300.0 : -20.0 * static_cast<double>(k % 3), due)) ++released;
    window.t_start_ns = t - 500'000;
    window.t_ns = t;
    delay.hold(window);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(released, 39'998U);
}

// RPEM_COMMAND's entry point (control thread) promises no allocation either, whatever the bytes —
// authentication (HMAC-SHA256 over the received bytes) included.
TEST(LoopAllocations, NoneInCommandAdmission) {
  rpem::command_t m{};
  m.seq = 7;
  m.command = rpem::command_t::SET_VALUES;
  m.psi_m_Wb = 1.1;
  m.r_s_Ohm = 2.3;
  std::array<std::uint8_t, auth::kKeyBytes> key_bytes{};
  key_bytes.fill(0x42);
  const auth::Key key(3, key_bytes);  // the supervisor's
  auth::Keyring keys;
  ASSERT_TRUE(keys.add(auth::Key(3, key_bytes)));  // rpemd's
  m.key_id = key.id();
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  ASSERT_EQ(m.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  ASSERT_TRUE(auth::sign(key, "RPEM_COMMAND", bytes));
  std::vector<std::uint8_t> forged(bytes);
  forged.back() ^= 1;
  std::vector<std::uint8_t> junk(bytes);
  junk[3] ^= 0x5A;
  const CommandPolicy policy{true, 0.5, 1.7, 1.0, 4.5, CommandAuthentication::kRequired};
  const long before = g_allocations.load();
  int admitted = 0;
  for (int k = 0; k < 1000; ++k) {
    admitted += admit_command(bytes, policy, keys, "RPEM_COMMAND", k % 10).result == CommandResult::kApplied;
    admitted += admit_command(forged, policy, keys, "RPEM_COMMAND", 0).result == CommandResult::kApplied;
    admitted += admit_command(junk, policy, keys, "RPEM_COMMAND", 0).decoded;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(admitted, 700);  // last accepted 0…6 of every 10: seq 7 is new
}

}  // namespace
}  // namespace rpem::daemon
