#include "rpem/daemon/publisher.hpp"

#include <poll.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "rpem/daemon/realtime.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/command_t.hpp"
#include "rpem/diagnostics_t.hpp"
#include "rpem/estimate_t.hpp"
#include "rpem/measurement_t.hpp"

namespace rpem::daemon {

struct Publisher::Lcm {
  explicit Lcm(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
};

namespace {

std::int64_t unix_us() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
}

}  // namespace

Publisher::Publisher(const DaemonConfig& config, std::string source_name, SpscQueue<Report>& reports,
                     SpscQueue<Command>& commands, const SourceStats& source_stats, StateFileStatus state_file_status)
    : config_(config),
      source_name_(std::move(source_name)),
      reports_(reports),
      commands_(commands),
      source_(source_stats),
      state_file_status_(state_file_status),
      buffer_(8192),
      state_path_(resolve_state_file(config)) {}

Publisher::~Publisher() = default;

bool Publisher::publish_raw(const std::string& channel, std::int64_t size) {
  if (size < 0 || !lcm_ || !lcm_->lcm.good() || lcm_->lcm.publish(channel, buffer_.data(), static_cast<unsigned>(size)) != 0) {
    counters_.publish_failures.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

void Publisher::publish_estimate(const EstimateReport& r) {
  rpem::estimate_t m;
  m.utime = r.utime_us;
  m.sample_time_us = r.sample_time_us;
  m.samples = r.samples;
  m.psi_m_Wb = r.psi_m_Wb;
  m.r_s_Ohm = r.r_s_Ohm;
  m.psi_m_pu = r.psi_m_pu;
  m.r_s_pu = r.r_s_pu;
  m.t_magnet_C = r.t_magnet_C;
  m.t_winding_C = r.t_winding_C;
  m.speed_pu = r.speed_pu;
  m.psi_m_valid = r.psi_m_valid;
  m.r_s_valid = r.r_s_valid;
  m.psi_m_converged = r.psi_m_converged;
  m.r_s_converged = r.r_s_converged;
  m.psi_m_adapting = r.psi_m_adapting;
  m.r_s_adapting = r.r_s_adapting;
  m.frozen = r.frozen;
  m.state = static_cast<std::int8_t>(r.state);
  m.algorithm = io::to_string(r.algorithm);
  if (publish_raw(channel("RPEM_ESTIMATE"), m.encode(buffer_.data(), 0, static_cast<int>(buffer_.size()))) &&
      r.newest_rx_ns > 0) {
    const double us = 1e-3 * static_cast<double>(unix_us() * 1000 - r.newest_rx_ns);
    rx_to_publish_.add(us);
    rx_to_publish_run_.add(us);
  }
}

void Publisher::publish_measurement(const MeasurementReport& r) {
  rpem::measurement_t m;
  m.utime = r.utime_us;
  m.sample_time_us = r.sample_time_us;
  m.theta_el_rad = r.theta_el_rad;
  m.omega_el_rad_s = r.omega_el_rad_s;
  m.u_dc_V = r.u_dc_V;
  m.i_d_A = r.i_d_A;
  m.i_q_A = r.i_q_A;
  m.i_hat_d_A = r.i_hat_d_A;
  m.i_hat_q_A = r.i_hat_q_A;
  m.epsilon_d_A = r.eps_d_A;
  m.epsilon_q_A = r.eps_q_A;
  publish_raw(channel("RPEM_MEASUREMENT"), m.encode(buffer_.data(), 0, static_cast<int>(buffer_.size())));
}

void Publisher::publish_diagnostics(const LoopStatsReport& r) {
  auto get = [](const std::atomic<std::int64_t>& a) { return a.load(std::memory_order_relaxed); };
  rpem::diagnostics_t m;
  m.utime = r.utime_us;
  m.state = static_cast<std::int8_t>(r.state);
  m.source = config_.source == SourceType::kCan ? "can" : "sim";
  m.source_name = source_name_;
  m.loop_period_ns = r.period_ns;
  m.wakeup_latency_min_us = r.latency_min_us;
  m.wakeup_latency_mean_us = r.latency_mean_us;
  m.wakeup_latency_max_us = r.latency_max_us;
  m.wakeup_latency_p99_us = r.latency_p99_us;
  m.loop_work_max_us = r.work_max_us;
  m.overruns = r.overruns;
  m.loop_periods = r.periods;
  m.rx_to_publish_p50_us = rx_to_publish_.percentile(0.5);
  m.rx_to_publish_p99_us = rx_to_publish_.percentile(0.99);
  m.rx_to_publish_max_us = rx_to_publish_.max();
  rx_to_publish_.reset();
  m.samples = r.samples;
  m.resyncs = r.resyncs;
  m.rejected_non_finite = r.rejected_non_finite;
  m.predictor_resets = r.predictor_resets;
  m.epsilon_rms_d_A = r.eps_rms_d_A;
  m.epsilon_rms_q_A = r.eps_rms_q_A;
  m.gain_norm = r.gain_norm;
  m.hessian_sga_psi_m_pu = r.hessian_sga_psi_m;
  m.hessian_sga_r_s_pu = r.hessian_sga_r_s;
  m.hessian_gna_det_pu = r.hessian_gna_det;
  m.projections = r.projections;
  m.can_frames = get(source_.frames);
  m.can_unknown_id = get(source_.unknown_id);
  m.can_wrong_dlc = get(source_.wrong_dlc);
  m.can_bad_version = get(source_.bad_version);
  m.can_crc_error = get(source_.crc_error);
  m.can_frames_lost = get(source_.frames_lost);
  m.can_duplicated = get(source_.duplicated);
  m.can_reordered = get(source_.reordered);
  m.can_stale = get(source_.stale);
  m.can_out_of_range = get(source_.out_of_range);
  m.can_invalid_value = get(source_.invalid_value);
  m.can_incomplete = get(source_.incomplete);
  m.can_gaps = get(source_.gaps);
  m.can_kernel_drops = get(source_.kernel_drops);
  m.can_reopens = get(source_.reopens);
  m.can_error_frames = get(source_.error_frames);
  m.can_bus_off = get(source_.bus_off);
  m.can_error_passive = get(source_.error_passive);
  m.can_controller_overflow = get(source_.controller_overflow);
  m.input_queue_depth = r.input_queue_depth;
  m.input_queue_drops = get(source_.queue_drops);
  m.output_queue_depth = static_cast<std::int32_t>(reports_.size());
  m.output_queue_drops = r.output_queue_drops;
  m.publish_failures = get(counters_.publish_failures);
  m.commands_enabled = config_.commands_enabled;
  m.commands_received = get(counters_.commands_received);
  m.commands_malformed = get(counters_.commands_malformed);
  m.commands_rejected = get(counters_.commands_rejected);
  // The newest verdict: the loop's for applied commands, ours for rejected ones.
  if (last_reject_seq_ > r.last_command_seq || (last_reject_ != CommandResult::kNone && r.last_command_seq == 0)) {
    m.last_command_seq = last_reject_seq_;
    m.last_command_result = static_cast<std::int8_t>(last_reject_);
  } else {
    m.last_command_seq = r.last_command_seq;
    m.last_command_result = static_cast<std::int8_t>(r.last_command_result);
  }
  m.state_file_status = static_cast<std::int8_t>(state_file_status_);
  m.state_writes = get(counters_.state_writes);
  m.state_write_failures = get(counters_.state_write_failures);
  m.config_reloads = r.config_reloads;
  m.config_reload_failures = get(counters_.config_reload_failures);
  publish_raw(channel("RPEM_DIAGNOSTICS"), m.encode(buffer_.data(), 0, static_cast<int>(buffer_.size())));
}

void Publisher::handle_command(const void* data, std::uint32_t size) {
  counters_.commands_received.fetch_add(1, std::memory_order_relaxed);
  rpem::command_t m;
  if (m.decode(data, 0, static_cast<int>(size)) < 0) {
    counters_.commands_malformed.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  auto reject = [&](CommandResult why) {
    counters_.commands_rejected.fetch_add(1, std::memory_order_relaxed);
    last_reject_ = why;
    last_reject_seq_ = m.seq;
  };
  if (!config_.commands_enabled) return reject(CommandResult::kRejectedDisabled);
  if (m.seq <= last_seq_accepted_) return reject(CommandResult::kRejectedOldSequence);
  Command c;
  c.seq = m.seq;
  switch (m.command) {
    case rpem::command_t::RESET:
      c.kind = Command::Kind::kReset;
      break;
    case rpem::command_t::FREEZE:
      c.kind = Command::Kind::kFreeze;
      break;
    case rpem::command_t::UNFREEZE:
      c.kind = Command::Kind::kUnfreeze;
      break;
    case rpem::command_t::SET_VALUES: {
      const auto& e = config_.machine.estimator;
      if (!(m.psi_m_Wb >= e.psi_m_min_Wb && m.psi_m_Wb <= e.psi_m_max_Wb && m.r_s_Ohm >= e.r_s_min_Ohm &&
            m.r_s_Ohm <= e.r_s_max_Ohm)) {
        return reject(CommandResult::kRejectedBadValues);
      }
      c.kind = Command::Kind::kSetValues;
      c.psi_m_Wb = m.psi_m_Wb;
      c.r_s_Ohm = m.r_s_Ohm;
      break;
    }
    default:
      return reject(CommandResult::kRejectedUnknown);
  }
  if (!commands_.push(c)) return reject(CommandResult::kRejectedUnknown);
  last_seq_accepted_ = m.seq;
}

void Publisher::maybe_write_state(bool force) {
  if (!have_estimate_) return;
  const EstimateReport& r = last_estimate_;
  if (!r.has_good_psi_m && !r.has_good_r_s) return;
  const std::int64_t now_s = std::time(nullptr);
  if (!force && now_s < next_state_write_s_) return;
  next_state_write_s_ = now_s + static_cast<std::int64_t>(config_.state_write_interval_s);
  PersistedEstimates e;
  e.written_unix_s = now_s;
  if (r.has_good_psi_m) e.psi_m_Wb = r.good_psi_m_Wb;
  if (r.has_good_r_s) e.r_s_Ohm = r.good_r_s_Ohm;
  const std::string problem = write_state_file(state_path_, e);
  if (problem.empty()) {
    counters_.state_writes.fetch_add(1, std::memory_order_relaxed);
  } else {
    counters_.state_write_failures.fetch_add(1, std::memory_order_relaxed);
    std::fprintf(stderr, "rpemd: cannot write the state file: %s\n", problem.c_str());
  }
}

void Publisher::print_status(const EstimateReport& r) {
  if (config_.status_interval_s <= 0.0 || r.utime_us < next_status_us_) return;
  next_status_us_ = r.utime_us + static_cast<std::int64_t>(config_.status_interval_s * 1e6);
  static const char* kStates[] = {"starting", "running", "STALE", "stopping"};
  const bool sim = source_.simulated.load(std::memory_order_relaxed);
  char truth[96] = "";
  if (sim) {
    std::snprintf(truth, sizeof truth, "  [sim truth %.4f Wb %.4f Ohm]", source_.truth_psi_m_Wb.load(),
                  source_.truth_r_s_Ohm.load());
  }
  std::printf("rpemd %-8s n=%+.3f pu  psi_m=%.4f Wb%s%s (T_magnet %5.1f C)  r_s=%.4f Ohm%s%s (T_winding %5.1f C)%s%s\n",
              kStates[static_cast<int>(r.state)], r.speed_pu, r.psi_m_Wb, r.psi_m_adapting ? "*" : " ",
              r.psi_m_valid ? "" : "?", r.t_magnet_C, r.r_s_Ohm, r.r_s_adapting ? "*" : " ", r.r_s_valid ? "" : "?",
              r.t_winding_C, truth, r.frozen ? "  FROZEN" : "");
  std::fflush(stdout);
}

void Publisher::run(std::atomic<bool>& stop) {
  name_thread("rpemd-publish");
  (void)apply_thread_policy(config_.realtime == RealtimeMode::kOff ? ThreadPolicy{} : config_.publish_thread);
  std::int64_t next_connect_us = 0;
  auto connect = [&] {
    if (lcm_ && lcm_->lcm.good()) return;
    const std::int64_t now = unix_us();
    if (now < next_connect_us) return;
    next_connect_us = now + 1'000'000;
    lcm_ = std::make_unique<Lcm>(config_.lcm_url);
    if (!lcm_->lcm.good()) {
      std::fprintf(stderr, "rpemd: LCM not available (%s); retrying\n", config_.lcm_url.empty() ? "default URL" : config_.lcm_url.c_str());
      return;
    }
    struct Handler {
      Publisher* self;
      void on(const lcm::ReceiveBuffer* rbuf, const std::string&) { self->handle_command(rbuf->data, rbuf->data_size); }
    };
    static thread_local Handler handler;
    handler.self = this;
    lcm_->lcm.subscribe(channel("RPEM_COMMAND"), &Handler::on, &handler);
  };
  connect();
  Report report;
  while (true) {
    bool any = false;
    while (reports_.pop(report)) {
      any = true;
      if (const auto* e = std::get_if<EstimateReport>(&report)) {
        last_estimate_ = *e;
        have_estimate_ = true;
        publish_estimate(*e);
        print_status(*e);
      } else if (const auto* m = std::get_if<MeasurementReport>(&report)) {
        publish_measurement(*m);
      } else if (const auto* d = std::get_if<LoopStatsReport>(&report)) {
        publish_diagnostics(*d);
      }
    }
    maybe_write_state(false);
    if (stop.load(std::memory_order_relaxed) && !any) break;
    connect();
    if (lcm_ && lcm_->lcm.good()) {
      pollfd pfd{lcm_->lcm.getFileno(), POLLIN, 0};
      if (::poll(&pfd, 1, any ? 0 : 5) > 0) lcm_->lcm.handleTimeout(0);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  maybe_write_state(true);
}

}  // namespace rpem::daemon
