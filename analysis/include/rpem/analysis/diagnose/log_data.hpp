#pragma once
// A drive log held in memory for `rpem diagnose`, with what the diagnosis needs to know about it: which
// model replays it (transient or steady state), which samples take part, and how they split into
// training and held-out blocks. The samples are kept once (SampleStore, about 90 bytes each); what the
// replay derives from them — the logged current in dq, the centred speed — is computed as it goes.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rpem/analysis/diagnose/sample_store.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/core/types.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/machine_config.hpp"

namespace rpem::analysis {

/// Transient logs (sampled at the control rate) replay the open-loop discrete predictor; logs whose
/// samples lie far apart against the electrical time constants replay the steady-state model.
enum class ModelMode { kTransient, kSteadyState };

[[nodiscard]] const char* to_string(ModelMode m) noexcept;

struct LogData {
  std::string path;
  std::string format;  ///< what the log was read as, and what reading it did (io::describe); a line per session
  /// The drive's reported commands were turned into the applied means at reading (LogOptions::voltage_is_command):
  /// whatever runs over the rows must not turn them again.
  bool voltage_applied = false;
  SampleStore samples;
  io::DriveLogLayout layout;
  ModelMode mode = ModelMode::kTransient;
  bool averaged = false;  ///< an averaged rotor-frame log (docs/drive-log.md, "Averaged logs"): always steady state
  /// Averaged logs: each row's window start (its t is the window's end); empty for phase-sample logs.
  std::vector<std::int64_t> window_start_ns;
  /// Averaged logs: what the regime classification is given beside the row, so that it classifies each window as
  /// `rpem estimate` does (issue 23: one classification for every consumer): the window's speed error and its noise as
  /// the reader states them (core::AveragedSample's omega_el_error_rad_s, omega_el_error_noise_rad_s), and its voltage
  /// as the drive reported it (before the turn of LogOptions::voltage_is_command, which the estimator makes itself:
  /// the classifier judges the reported value's resolution and zero).
  std::vector<double> window_speed_error_rad_s, window_speed_error_noise_rad_s;
  /// ... and the larger |speed| at its two reads (core::AveragedSample::omega_el_at_reads_max_rad_s; NaN: none).
  std::vector<double> window_speed_at_reads_max_rad_s;
  std::vector<core::Vec2> window_reported_u_V;
  /// Averaged logs, per session: whether its voltages were rebuilt (io::RotorFrameRebuild; applied means, which the
  /// estimator must not turn: io::estimator_settings).
  std::vector<bool> session_voltage_rebuilt;
  /// Samples of sessions with rebuilt voltages left out because the folder's other sessions log d/q voltages
  /// (leave_out_rebuilt_sessions): those alone carry the constants a rebuilt u_d holds at their configured values.
  std::size_t excluded_rebuilt = 0;
  double t_start_s = 0.0, t_end_s = 0.0;
  double median_dt_s = 0.0;
  double max_current_A = 0.0;    ///< largest measured current amplitude
  double max_speed_rad_s = 0.0;  ///< largest |ω_el|
  /// How far the speed varies in motion: the 10th to 90th percentile of |ω_el| over the samples above 5 %
  /// of the largest, relative to the largest (0: one speed).
  double speed_spread_rel = 0.0;
  double mean_u_dc_V = 0.0;
  /// Transient logs: the replay takes the electrical speed as the centred difference of the logged angle
  /// over ±this many samples (replay_sample) — no lag, unlike a drive's causal speed signal; 0: as logged.
  /// The estimator runs see the logged speed, as the drive gave it.
  int speed_half_window = 0;
  std::size_t excluded_idle = 0, excluded_transitional = 0;
  /// Training and held-out blocks, alternating, equal in the time the log sampled (its pauses left out):
  /// block b holds the samples [block_first[b], block_first[b + 1]); even blocks train, odd blocks are held out.
  int blocks = 0;
  std::vector<std::size_t> block_first;
  /// The log's pauses — intervals longer than kPauseMedianIntervals times the median one (two recordings
  /// joined, a logger paused) — which the blocks' time leaves out: how many and the longest [s].
  static constexpr double kPauseMedianIntervals = 20.0;
  std::size_t pauses = 0;
  double longest_pause_s = 0.0;
  /// A folder's logs are one machine's sessions, joined (load_sessions): session j holds the samples
  /// [session_first[j], session_first[j + 1]) (the last to the end) and was read from session_logs[j]. Each
  /// session's samples follow the last one's after kSessionGap_ns (1 s) on t; its first is marked gap_before, so that
  /// every replay and estimator starts afresh there, and the blocks' time counts nothing between sessions.
  /// One log is one session.
  static constexpr std::int64_t kSessionGap_ns = core::kNsPerS;
  std::vector<std::size_t> session_first{0};
  std::vector<std::string> session_logs;

  [[nodiscard]] std::size_t size() const noexcept { return samples.size(); }
  /// Whether samples whose voltages were rebuilt from the duty cycle take part (effects.cpp: withheld_constants).
  [[nodiscard]] bool uses_rebuilt_voltages() const noexcept {
    return excluded_rebuilt == 0 &&
           std::any_of(session_voltage_rebuilt.begin(), session_voltage_rebuilt.end(), [](bool r) { return r; });
  }
  [[nodiscard]] std::size_t sessions() const noexcept { return session_first.size(); }
  /// One past session j's last sample.
  [[nodiscard]] std::size_t session_end(std::size_t j) const noexcept {
    return j + 1 < session_first.size() ? session_first[j + 1] : size();
  }
  /// Whether sample k opens a session after the first (the replays and estimators restart there).
  [[nodiscard]] bool starts_session(std::size_t k) const noexcept {
    return k > 0 && std::binary_search(session_first.begin(), session_first.end(), k);
  }
  /// Sample k as logged.
  [[nodiscard]] core::DriveSample sample(std::size_t k) const noexcept { return samples.sample(k); }
  /// Sample k as the replay takes it: with the centred speed (see speed_half_window).
  [[nodiscard]] core::DriveSample replay_sample(std::size_t k) const noexcept;
  /// The logged current as dq at the logged angle [A]: what every model is compared with.
  [[nodiscard]] core::Vec2 logged_i_dq_A(std::size_t k) const noexcept;
  [[nodiscard]] double t_s(std::size_t k) const noexcept { return core::to_seconds(samples.t_ns(k)); }

  /// Whether sample k takes part (steady state leaves out idle and transitional rows; every log the samples
  /// its regime excludes, regimes.hpp).
  [[nodiscard]] bool used(std::size_t k) const noexcept { return (samples.mark(k) & sample_mark::kLeftOut) == 0; }
  /// Samples that take part.
  [[nodiscard]] std::size_t used_count() const noexcept;
  /// The block of sample k.
  [[nodiscard]] int block(std::size_t k) const noexcept {
    return static_cast<int>(std::upper_bound(block_first.begin(), block_first.end(), k) - block_first.begin()) - 1;
  }
  /// Where sample k lies in the log's time span, 0 … 1.
  [[nodiscard]] double time_fraction(std::size_t k) const noexcept {
    return (t_s(k) - t_start_s) / std::max(t_end_s - t_start_s, 1e-12);
  }
  [[nodiscard]] bool training(std::size_t k) const noexcept { return used(k) && block(k) % 2 == 0; }
  [[nodiscard]] bool heldout(std::size_t k) const noexcept { return used(k) && block(k) % 2 == 1; }
  /// Samples of training blocks that take part.
  [[nodiscard]] std::size_t training_count() const noexcept;
  /// Heap bytes the log holds.
  [[nodiscard]] std::size_t bytes() const noexcept {
    return samples.bytes() + block_first.capacity() * sizeof(std::size_t) +
           window_start_ns.capacity() * sizeof(std::int64_t);
  }
};

/// The mean a reported command applies in the rotor frame over the period it is held (docs/derivations.md
/// §11, "Reported command"): the command v, computed at the current sample's angle and held fixed in the
/// stator frame over [d − ½, d + ½]·T_c after it, arrives turned by −ω·d·T_c and shortened by sinc(ω·T_c/2).
[[nodiscard]] core::Vec2 applied_mean_V(const core::Vec2& command_V, double omega_el_rad_s, double control_period_s,
                                        double delay_periods) noexcept;

struct LogOptions {
  std::optional<ModelMode> mode;  ///< empty: decided from the sample interval
  /// An averaged log whose voltages are the drive's command (estimator.averaged.voltage_reported: command): its
  /// T_c and the delay before the hold (model_extensions.delay), which reading turns into the applied mean.
  bool voltage_is_command = false;
  double control_period_s = 0.0;
  double command_delay_s = 0.0;
  /// estimator.regimes.hall_interpolation_speed_rad_s: below it an averaged window's speed is its step count's
  /// (core::window_speed_rad_s); 0: the reported speed everywhere.
  double staircase_below_rad_s = 0.0;
  int blocks = 40;  ///< training and held-out blocks, alternating, equal in sampled time
  /// What the caller needs the samples for, said where a log has too few (empty: the blocks, as diagnose does).
  std::string samples_needed_for;
  int speed_half_window = 4;  ///< transient logs: replay speed from the angle over ±this many samples
  std::string log_map;        ///< a column map (YAML) to read the log with; empty: detected (io::log_source)
};

/// The options a configuration decides (the reported voltage's kind, the command's timing, the Hall staircase);
/// the rest at their defaults.
[[nodiscard]] LogOptions log_options(const io::MachineConfig& config);

/// Where the steady-state replay left out more than io::kExplainedShare of the rows as idle or in transition:
/// one sentence per rule, how many, why, and what changes it (docs/diagnose.md, "The replay").
[[nodiscard]] std::vector<std::string> left_out_explanations(const LogData& log);

/// A log whose training or held-out blocks keep fewer than 2 samples once every exclusion is made (a log of a
/// machine at rest, a bridge off throughout) has nothing to fit or judge: io::DriveLogError, "nothing to
/// diagnose", with `why` (the exclusions' explanations) appended.
void require_samples_to_fit(const LogData& log, const std::vector<std::string>& why);

/// Loads and characterises a log, a phase-sample or an averaged one, in any format io::log_source reads
/// (throws io::DriveLogError on bad input, io::ConfigError on a bad map). `progress`, if given, is told the
/// bytes read of the file's total as it goes.
[[nodiscard]] LogData load_log(const std::string& path, const core::MachineSi& machine, const LogOptions& options,
                               const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

/// The logs of a folder (in `paths`' order, at least one), one machine's sessions, named `name` (the folder): each
/// read as load_log reads it, then joined one after another on one time axis (LogData::session_first). The logs
/// must be alike — all averaged or all instantaneous, with the same columns — and each must give its samples: else
/// io::DriveLogError naming the log (a diagnosis without one of them would be another diagnosis).
[[nodiscard]] LogData load_sessions(const std::string& name, const std::vector<std::string>& paths,
                                    const core::MachineSi& machine, const LogOptions& options,
                                    const std::function<void(std::uint64_t, std::uint64_t)>& progress = {});

/// The same from rows already in memory (tests, the simulator).
[[nodiscard]] LogData prepare_log(const std::vector<io::DriveLogRow>& rows, const io::DriveLogLayout& layout,
                                  const core::MachineSi& machine, const LogOptions& options,
                                  const std::string& path = "<memory>");

/// Characterises a log whose samples are stored (`d.samples` finished, `d.path` set): what load_log and
/// prepare_log share.
void prepare_log(LogData& d, const core::MachineSi& machine, const LogOptions& options);

}  // namespace rpem::analysis
