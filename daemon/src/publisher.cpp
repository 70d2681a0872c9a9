#include "rpem/daemon/publisher.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <lcm/lcm-cpp.hpp>
#include <span>
#include <thread>

#include "rpem/core/clock.hpp"
#include "rpem/daemon/realtime.hpp"
#include "rpem/daemon/status_line.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/thermal_config.hpp"
#include "rpem/measurement_t.hpp"
#include "rpem/mirror/diagnostics_t.hpp"
#include "rpem/schema/field.hpp"

namespace rpem::daemon {

struct PersistingPublisher::Lcm {
  explicit Lcm(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
};

namespace {

using Diag = rpem::diagnostics_t;

constexpr std::array<CounterRow<PublisherCounters>, 3> kPublisherRows{{
    {&PublisherCounters::publish_failures, &Diag::publish_failures},
    {&PublisherCounters::state_writes, &Diag::state_writes},
    {&PublisherCounters::state_write_failures, &Diag::state_write_failures},
}};

}  // namespace

std::int64_t publisher_idle_ns(const LcmConfig& lcm) noexcept {
  constexpr std::int64_t kMinNs = 1'000'000, kMaxNs = 20'000'000;
  const double fastest_Hz = std::max({lcm.estimate_rate_Hz, lcm.measurement_rate_Hz, lcm.diagnostics_rate_Hz});
  if (!(fastest_Hz > 0.0)) return kMaxNs;
  return std::clamp(static_cast<std::int64_t>(std::llround(0.5e9 / fastest_Hz)), kMinNs, kMaxNs);
}

PersistingPublisher::PersistingPublisher(const FixedConfig& config, Identity identity, Queues queues,
                                         std::optional<auth::Key> publish_key)
    : config_(config),
      identity_(std::move(identity)),
      publish_key_(std::move(publish_key)),
      queues_(std::move(queues)),
      buffer_(8192),
      estimate_channel_(config.lcm.channel_prefix + "RPEM_ESTIMATE"),
      measurement_channel_(config.lcm.channel_prefix + "RPEM_MEASUREMENT"),
      diagnostics_channel_(config.lcm.channel_prefix + "RPEM_DIAGNOSTICS"),
      state_path_(resolve_state_file(config.state)),
      thermal_(identity_.resumed_thermal) {}

PersistingPublisher::~PersistingPublisher() = default;

template <class Message>
void PersistingPublisher::publish(const std::string& channel, Message& m) {
  constexpr bool kAuthenticated = requires { m.key_id; };
  if constexpr (kAuthenticated) m.key_id = publish_key_ ? publish_key_->id() : 0;
  const int size = m.encode(buffer_.data(), 0, static_cast<int>(buffer_.size()));
  // Signed in the buffer, on this thread: the tag over the encoding (rpem/auth/mac.hpp), no allocation.
  if constexpr (kAuthenticated) {
    if (size > 0 && publish_key_)
      (void)auth::sign(*publish_key_, channel, std::span(buffer_.data(), static_cast<std::size_t>(size)));
  }
  if (size < 0 || !lcm_ || !lcm_->lcm.good() ||
      lcm_->lcm.publish(channel, buffer_.data(), static_cast<unsigned>(size)) != 0) {
    ++counters_.publish_failures;
  }
}

// Every field of the mirror, generically (rpem/schema/field.hpp); the strings, which the mirror does not
// carry, by hand: a new string field fails the static_assert until it is spelled here.
void PersistingPublisher::publish_estimate(const EstimateReport& r) {
  rpem::estimate_t m{};
  schema::copy(r, m);
  static_assert(schema::spelled_count<rpem::estimate_t>() == 1, "estimate_t's strings: algorithm");
  m.algorithm = io::to_string(r.algorithm);
  const std::int64_t failures = counters_.publish_failures;
  publish(estimate_channel_, m);
  if (counters_.publish_failures == failures && r.newest_rx_ns > 0) {
    const double us = 1e-3 * static_cast<double>(core::unix_us() * 1000 - r.newest_rx_ns);
    rx_to_publish_.add(us);
    rx_to_publish_run_.add(us);
  }
}

void PersistingPublisher::publish_measurement(const MeasurementReport& r) {
  rpem::measurement_t m{};
  schema::copy(r, m);
  static_assert(schema::spelled_count<rpem::measurement_t>() == 0);
  publish(measurement_channel_, m);
}

void PersistingPublisher::publish_diagnostics(const LoopStatsReport& r) {
  rpem::diagnostics_t m{};
  m.utime = r.utime_us;
  m.state = static_cast<std::int8_t>(r.state);
  static_assert(schema::spelled_count<rpem::diagnostics_t>() == 2, "diagnostics_t's strings: source, source_name");
  m.source = identity_.source_type;
  m.source_name = identity_.source_name;
  // Every counter and figure, from the thread that owns it.
  r.rows.write_to(m);
  source_.rows.write_to(m);
  control_.rows.write_to(m);
  DiagnosticsRows own;
  own.set_all(kPublisherRows, counters_);
  own.set(&Diag::rx_to_publish_p50_us, rx_to_publish_.percentile(0.5));
  own.set(&Diag::rx_to_publish_p99_us, rx_to_publish_.percentile(0.99));
  own.set(&Diag::rx_to_publish_max_us, rx_to_publish_.max());
  own.write_to(m);
  rx_to_publish_.reset();
  m.input_queue_depth = r.input_queue_depth;
  m.output_queue_depth = static_cast<std::int32_t>(queues_.loop.size());
  m.commands_enabled = static_cast<std::int8_t>(control_.commands_enabled ? 1 : 0);
  m.last_command_seq = control_.last_command_seq;
  m.last_command_result = static_cast<std::int8_t>(control_.last_command_result);
  m.state_file_status = static_cast<std::int8_t>(identity_.state_file_status);
  publish(diagnostics_channel_, m);
}

void PersistingPublisher::maybe_write_state(bool force) {
  if (!have_estimate_) return;
  const EstimateReport& r = last_estimate_;
  const double report_s = 1e-6 * static_cast<double>(r.utime);
  if (r.thermal.nodes > 0) thermal_ = {r.thermal, static_cast<std::int64_t>(report_s)};
  const std::int64_t now_s = std::time(nullptr);
  if (static_cast<double>(now_s - thermal_.at_unix_s) > config_.state.max_age_s) thermal_ = PersistedThermal{};
  if (!r.has_good_psi_m && !r.has_good_r_s && thermal_.state.nodes == 0) return;
  if (!force && now_s < next_state_write_s_) return;
  next_state_write_s_ = now_s + static_cast<std::int64_t>(config_.state.write_interval_s);
  PersistedEstimates e;
  e.written_unix_s = now_s;
  e.thermal = thermal_;
  if (r.has_good_psi_m) {
    e.psi_m_Wb = r.good_psi_m_Wb;
    e.psi_m_adapted_unix_s = static_cast<std::int64_t>(report_s - r.good_psi_m_age_s);
  }
  if (r.has_good_r_s) {
    e.r_s_Ohm = r.good_r_s_Ohm;
    e.r_s_adapted_unix_s = static_cast<std::int64_t>(report_s - r.good_r_s_age_s);
  }
  const std::string problem = write_state_file(state_path_, e);
  if (problem.empty()) {
    ++counters_.state_writes;
  } else {
    ++counters_.state_write_failures;
    std::fprintf(stderr, "rpemd: cannot write the state file: %s\n", problem.c_str());
  }
}

void PersistingPublisher::say_untested_start(const EstimateReport& r) {
  if (said_untested_start_ || !r.thermal_start_untested_by_sensor) return;
  said_untested_start_ = true;
  const std::string note = io::soaked_start_note(
      "no thermal state was resumed, and the winding sensor (thermal.winding_sensor) gave no reading in the filter's "
      "first step to test it");
  std::fprintf(stderr, "rpemd: note: %s\n", note.c_str());
}

void PersistingPublisher::print_status(const EstimateReport& r) {
  if (config_.status_interval_s <= 0.0 || r.utime < next_status_us_) return;
  next_status_us_ = r.utime + static_cast<std::int64_t>(config_.status_interval_s * 1e6);
  std::printf("%s\n", status_line(r, source_).c_str());
  std::fflush(stdout);
}

void PersistingPublisher::connect() {
  if (lcm_ && lcm_->lcm.good()) return;
  const std::int64_t now = core::unix_us();
  if (now < next_connect_us_) return;
  next_connect_us_ = now + 1'000'000;
  lcm_ = std::make_unique<Lcm>(config_.lcm.url);
  if (!lcm_->lcm.good()) {
    std::fprintf(stderr, "rpemd: LCM not available for publishing (%s); retrying\n",
                 config_.lcm.url.empty() ? "default URL" : config_.lcm.url.c_str());
  }
}

void PersistingPublisher::drain_reports() {
  SourceReport s;
  while (queues_.source.pop(s)) source_ = s;
  ControlReport c;
  while (queues_.control.pop(c)) control_ = c;
}

void PersistingPublisher::run(const std::atomic<bool>& stop) {
  name_thread("rpemd-publish");
  (void)apply_thread_policy(config_.loop.realtime == RealtimeMode::kOff ? ThreadPolicy{} : config_.publish_thread);
  connect();
  const std::chrono::nanoseconds idle(publisher_idle_ns(config_.lcm));
  Report report;
  while (true) {
    drain_reports();
    bool any = false;
    while (queues_.loop.pop(report)) {
      any = true;
      if (const auto* e = std::get_if<EstimateReport>(&report)) {
        last_estimate_ = *e;
        have_estimate_ = true;
        publish_estimate(*e);
        print_status(*e);
        say_untested_start(*e);
      } else if (const auto* m = std::get_if<MeasurementReport>(&report)) {
        publish_measurement(*m);
      } else if (const auto* d = std::get_if<LoopStatsReport>(&report)) {
        drain_reports();
        publish_diagnostics(*d);
      }
    }
    maybe_write_state(false);
    if (stop.load(std::memory_order_relaxed) && !any) break;
    connect();
    if (!any) std::this_thread::sleep_for(idle);
  }
  maybe_write_state(true);
}

}  // namespace rpem::daemon
