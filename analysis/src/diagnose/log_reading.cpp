// Reading logs into a LogData: one log (load_log), or a folder's logs joined as one machine's sessions
// (load_sessions). Both append each log's samples as it is read (SessionJoiner), so that a long recording is
// never held twice.
#include <cstdio>
#include <optional>

#include "rpem/analysis/diagnose/log_data.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/reported_speed.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/rotor_frame_rebuild.hpp"

namespace rpem::analysis {
namespace {

/// Turns a drive's reported commands into the applied means (LogOptions::voltage_is_command); returns what it
/// did, for the log's description.
std::string apply_reported_command(std::vector<core::AveragedSample>& samples, const LogOptions& options) {
  // Held one period from the delay on: its centre d·T_c = delay + T_c/2 after the sample. Every sample, the
  // bridge-off ones too: at VESC Tool's 0.01 A a modulating bridge at zero current reads i = 0 as well, and the
  // undriven branch's measured back EMF is then turned too (docs/drive-log.md, "The voltage is the command").
  const double d = (options.command_delay_s + 0.5 * options.control_period_s) / options.control_period_s;
  for (core::AveragedSample& s : samples) s.u_dq_V = applied_mean_V(s.u_dq_V, s.omega_el_rad_s, options.control_period_s, d);
  char text[200];
  std::snprintf(text, sizeof text,
                "; voltages reported as the drive's command, turned into the applied mean (by −%.3g·ω·T_c, times "
                "sinc(ω·T_c/2), T_c = %.3g µs)",
                d, 1e6 * options.control_period_s);
  return text;
}

/// The columns in which two logs' layouts differ, of those a LogData keeps ("" where none does).
std::string layout_difference(const io::DriveLogLayout& a, const io::DriveLogLayout& b) {
  std::string out;
  const auto differ = [&](bool x, bool y, const char* name) {
    if (x != y) out += (out.empty() ? "" : ", ") + std::string(name) + (x ? " (here, not there)" : " (there, not here)");
  };
  differ(a.angle, b.angle, "theta_el");
  differ(a.u_dc, b.u_dc, "u_dc");
  differ(a.voltage_abc, b.voltage_abc, "u_abc");
  differ(a.voltage_dq, b.voltage_dq, "u_dq");
  differ(a.current_abc, b.current_abc, "i_abc");
  differ(a.current_dq, b.current_dq, "i_dq");
  differ(a.t_winding, b.t_winding, "t_winding");
  differ(a.t_magnet, b.t_magnet, "t_magnet");
  return out;
}

/// Appends logs to a LogData one after another, each a session: its times shifted so that it starts
/// LogData::kSessionGap_ns after the last sample appended, its first sample marked gap_before.
class SessionJoiner {
 public:
  SessionJoiner(LogData& d, const core::MachineSi& machine, const LogOptions& options)
      : d_(d), machine_(machine), options_(options), limits_(io::machine_limits(machine)) {
    limits_.control_period_s = options.control_period_s;  // io::log_limits' from the configuration
  }

  void append(const std::string& path, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
    const io::LogSource source = io::log_source(path, options_.log_map);
    const std::size_t first = d_.samples.size();
    std::string format = source.averaged() ? append_averaged(path, source) : append_instantaneous(path, source, progress);
    if (d_.samples.size() == first) throw io::DriveLogError(path, 0, 0, "", "the log gives no sample");
    if (!d_.session_logs.empty()) d_.session_first.push_back(first);
    d_.session_logs.push_back(path);
    formats_ += (formats_.empty() ? "" : "\n") + format;
  }

  /// Completes the store and characterises the whole (prepare_log).
  void finish() {
    d_.samples.finish();
    LogOptions options = options_;
    // Window means carry no transient to replay: the steady-state model, whatever the spacing.
    if (d_.averaged) options.mode = ModelMode::kSteadyState;
    prepare_log(d_, machine_, options);
    d_.format = formats_;
  }

 private:
  std::string append_averaged(const std::string& path, const io::LogSource& source) {
    if (options_.mode == ModelMode::kTransient) {
      throw io::DriveLogError(path, 0, 0, "",
                              "a log of averaged windows (" + source.format +
                                  ") replays only the steady-state model: give --model auto or steady_state");
    }
    io::AveragedLogRead read;
    std::vector<core::AveragedSample> samples = io::read_averaged_log(path, source.map, limits_, &read);
    for (core::AveragedSample& s : samples) s.omega_el_rad_s = core::window_speed_rad_s(s, options_.staircase_below_rad_s);
    const io::RotorFrameRebuild rebuilt = io::complete_rotor_frame(
        samples, read, machine_, options_.voltage_is_command ? options_.control_period_s : 0.0, path);
    // Rebuilt voltages are applied rotor-frame means already: not turned again.
    const bool turn = options_.voltage_is_command && options_.control_period_s > 0.0 && !rebuilt.voltages;
    for (const core::AveragedSample& s : samples) d_.window_reported_u_V.push_back(s.u_dq_V);
    const std::string voltage = turn ? apply_reported_command(samples, options_) : "";
    open(path, io::rotor_frame_layout(read.layout), true);
    d_.session_voltage_rebuilt.push_back(rebuilt.voltages);
    d_.window_start_ns.reserve(d_.window_start_ns.size() + samples.size());
    d_.window_speed_error_rad_s.reserve(d_.window_speed_error_rad_s.size() + samples.size());
    d_.window_speed_error_noise_rad_s.reserve(d_.window_speed_error_noise_rad_s.size() + samples.size());
    d_.window_speed_at_reads_max_rad_s.reserve(d_.window_speed_at_reads_max_rad_s.size() + samples.size());
    for (core::AveragedSample& s : samples) {
      const std::int64_t shift = shift_ns(s.t_start_ns);
      s.t_start_ns += shift;
      s.t_ns += shift;
      push(io::to_drive_log_row(s));
      d_.window_start_ns.push_back(s.t_start_ns);
      d_.window_speed_error_rad_s.push_back(s.omega_el_error_rad_s);
      d_.window_speed_error_noise_rad_s.push_back(s.omega_el_error_noise_rad_s);
      d_.window_speed_at_reads_max_rad_s.push_back(s.omega_el_at_reads_max_rad_s);
    }
    d_.voltage_applied = d_.voltage_applied || turn || rebuilt.voltages;
    return io::describe(source, read) + voltage + (rebuilt.any() ? "; " + rebuilt.describe() : "");
  }

  std::string append_instantaneous(const std::string& path, const io::LogSource& source,
                                   const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
    io::DriveLogReader reader(path, source.map, limits_);
    open(path, reader.layout(), false);
    io::DriveLogRow row;
    std::size_t rows = 0;
    while (reader.next(row)) {
      row.sample.t_ns += shift_ns(row.sample.t_ns);
      push(row);
      ++rows;
      if (progress && (rows & 0xFFFF) == 0) progress(reader.bytes_read(), reader.bytes_total());
    }
    return path + " as " + source.format + ": " + std::to_string(rows) + " rows" + io::describe(reader.reader().repairs());
  }

  /// A log's layout: the first opens the store; every later one must be alike.
  void open(const std::string& path, const io::DriveLogLayout& layout, bool averaged) {
    session_shift_.reset();
    if (d_.session_logs.empty()) {
      d_.layout = layout;
      d_.averaged = averaged;
      d_.samples = SampleStore(layout);
      return;
    }
    const std::string& first = d_.session_logs.front();
    if (averaged != d_.averaged) {
      throw io::DriveLogError(path, 0, 0, "",
                              std::string(averaged ? "a log of averaged windows, " : "a log of instantaneous samples, ") +
                                  "but " + first + " is not: a folder's logs are one logger's sessions, alike");
    }
    if (const std::string diff = layout_difference(layout, d_.layout); !diff.empty()) {
      throw io::DriveLogError(path, 0, 0, "",
                              "its columns differ from " + first + "'s: " + diff +
                                  "; a folder's logs are one logger's sessions, with the same columns");
    }
  }

  /// The shift of the current log's times: none for the first log; for a later one, what puts its first time
  /// kSessionGap_ns after the last sample appended (decided at its first time).
  std::int64_t shift_ns(std::int64_t t_ns) {
    if (!session_shift_) {
      session_shift_ = d_.samples.empty() ? 0 : last_t_ns_ + LogData::kSessionGap_ns - t_ns;
      opens_session_ = !d_.samples.empty();
    }
    return *session_shift_;
  }

  void push(io::DriveLogRow row) {
    if (opens_session_) {
      row.sample.gap_before = true;  // nothing carries over from the last session
      d_.samples.start_session();    // not its temperatures either
    }
    opens_session_ = false;
    last_t_ns_ = row.sample.t_ns;
    d_.samples.push_back(row);
  }

  LogData& d_;
  const core::MachineSi& machine_;
  const LogOptions& options_;
  io::DriveLogLimits limits_;
  std::string formats_;
  std::optional<std::int64_t> session_shift_;
  bool opens_session_ = false;
  std::int64_t last_t_ns_ = 0;
};

}  // namespace

LogData load_log(const std::string& path, const core::MachineSi& machine, const LogOptions& options,
                 const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  LogData d;
  d.path = path;
  SessionJoiner joiner(d, machine, options);
  joiner.append(path, progress);
  joiner.finish();
  return d;
}

LogData load_sessions(const std::string& name, const std::vector<std::string>& paths, const core::MachineSi& machine,
                      const LogOptions& options, const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  if (paths.empty()) throw io::DriveLogError(name, 0, 0, "", "no log to read");
  LogData d;
  d.path = name;
  SessionJoiner joiner(d, machine, options);
  for (const std::string& path : paths) joiner.append(path, progress);
  joiner.finish();
  return d;
}

}  // namespace rpem::analysis
