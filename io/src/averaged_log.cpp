#include "rpem/io/averaged_log.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "rpem/core/assert.hpp"
#include "rpem/core/clock.hpp"
#include "rpem/core/reported_speed.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
namespace {

/// The count's quantum as the log shows it: the smallest change between consecutive reads (0: it never changed).
double count_step_rad(const std::vector<core::CountRead>& reads) {
  double step = 0.0;
  for (std::size_t j = 1; j < reads.size(); ++j) {
    const double change = std::abs(reads[j].travel_el_rad - reads[j - 1].travel_el_rad);
    if (change > 0.0 && (step == 0.0 || change < step)) step = change;
  }
  return step;
}

/// Each window's counted speed over the centred run of reads around it, grown while its sides agree
/// (core::grown_count_speed_rad_s; docs/derivations.md §13). `ends[k]` is the read that ends window k; a window
/// that does not start at the read before it (a log of windows with their own starts) has no count.
void set_counted_speeds(std::vector<core::AveragedSample>& out, const std::vector<core::CountRead>& reads,
                        const std::vector<std::size_t>& ends, double step_rad) {
  const auto side_max_ns = static_cast<std::int64_t>(core::kCountRunSideMaxS * 1e9);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t e = ends[k];
    if (e == 0 || reads[e - 1].t_ns != out[k].t_start_ns) continue;
    out[k].omega_counted_el_rad_s = core::grown_count_speed_rad_s(reads, e - 1, e, step_rad, side_max_ns);
  }
}

/// One row of a log whose windows run from the row before (window: previous_row), as read.
struct PreviousRowRead {
  core::AveragedSample sample;          ///< t_ns and the means; the window and its speed once they are known
  double omega_at_read_rad_s = 0.0;     ///< the speed column as it is (a PLL's at the read, or the window's mean)
  double travel_el_rad = std::nan("");  ///< the drive's count at the read (NaN: the log has none)
  double duty = std::nan("");           ///< the duty cycle at the read (NaN: the log has none)
  double i_motor_A = std::nan("");      ///< the motor current's mean (NaN: the log has none)
  std::size_t line = 0;                 ///< where the row is, for errors
};

/// A sample's own values beside its means, and the duty at the read that starts its window (`start`; none: not
/// known): kept with the samples, in their order.
void keep_extras(const PreviousRowRead& row, const PreviousRowRead* start, AveragedLogRead& read) {
  if (read.layout.duty) {
    read.duty.push_back(row.duty);
    read.duty_at_start.push_back(start ? start->duty : std::nan(""));
    read.u_dc_at_start_V.push_back(start ? start->sample.u_dc_V : std::nan(""));
  }
  if (read.layout.i_motor) read.i_motor_A.push_back(row.i_motor_A);
}

/// Which reads' times and which windows a previous_row log leaves unknown (docs/drive-log.md, "Rows stamped late").
struct UnknownTiming {
  std::vector<bool> read;    ///< row k's read may lie long before its stamp
  std::vector<bool> window;  ///< row k's window (from row k − 1's read) is unknown
};

/// The most window j's count can move (j ≥ 2: the bound needs row j − 2's arrival): a logger that asks only while no
/// request is outstanding took read j − 1 after row j − 2 arrived and read j before row j did, so the count moves at
/// most the faster of its two speeds read over t_j − t_{j−2}, plus the rotor's lead over a PLL's speed (lag·|Δω̂|) and
/// the count's 2 steps (core::grown_count_speed_rad_s).
double window_count_allowance_rad(const std::vector<PreviousRowRead>& rows, std::size_t j, const LogMap& map,
                                  double step_rad) {
  RPEM_ASSERT(j >= 2 && j < rows.size(), "the bound needs row j − 2's arrival");
  const PreviousRowRead& a = rows[j - 1];
  const PreviousRowRead& b = rows[j];
  const double reads_apart_s = core::to_seconds(b.sample.t_ns - rows[j - 2].sample.t_ns);
  const double speed_rad_s = std::max(std::abs(a.omega_at_read_rad_s), std::abs(b.omega_at_read_rad_s));
  return speed_rad_s * reads_apart_s + map.speed_pll.ramp_lag_s() * std::abs(b.omega_at_read_rad_s - a.omega_at_read_rad_s) +
         2.0 * step_rad;
}

/// A read at an unknown time ends one window and starts the next, so both are unknown. A read is:
/// - row k, `request_timeout_s` or more after row k − 1 and at least 1.5 of the log's median spacing: the logger asked
///   again, and the request it gave up on may have been read (the means reset then) and be answered only now. A
///   logger polling slower than its timeout spaces its rows by about its poll period P (each reply in before the
///   next tick), and a request it gave up on costs a tick: 2P, so a row is judged against the midpoint as well;
///   polling faster, the timeout decides;
/// - row k, a stale reply arriving out of order: its count steps back against the motion and forward again, each
///   step further than the reads can lie apart (window_count_allowance_rad). One window beyond that could be a speed
///   read wrong (a Hall drive's PLL at a crawl follows a staircase); two beside one read, in opposite directions, is
///   a read out of its place.
UnknownTiming unknown_timing(const std::vector<PreviousRowRead>& rows, const LogMap& map, double step_rad) {
  const std::size_t n = rows.size();
  std::vector<std::int64_t> spacing_ns;
  spacing_ns.reserve(n);
  for (std::size_t k = 1; k < n; ++k) spacing_ns.push_back(rows[k].sample.t_ns - rows[k - 1].sample.t_ns);
  double median_spacing_s = 0.0;
  if (!spacing_ns.empty()) {
    const auto middle = spacing_ns.begin() + static_cast<std::ptrdiff_t>(spacing_ns.size() / 2);
    std::nth_element(spacing_ns.begin(), middle, spacing_ns.end());
    median_spacing_s = core::to_seconds(*middle);
  }
  const double asked_again_s = std::max(map.request_timeout_s, 1.5 * median_spacing_s);
  UnknownTiming u{std::vector<bool>(n, false), std::vector<bool>(n, false)};
  const auto unknown_read = [&](std::size_t j) {
    u.read[j] = true;
    u.window[j] = true;
    if (j + 1 < n) u.window[j + 1] = true;
  };
  if (n > 0) u.window[0] = true;  // the first row's window began before the log
  // Window j's count beyond what the reads allow, signed by its direction (0: within, or no count); j ≥ 2.
  const auto excess = [&](std::size_t j) {
    const double travel_rad = rows[j].travel_el_rad - rows[j - 1].travel_el_rad;
    return step_rad > 0.0 && std::abs(travel_rad) > window_count_allowance_rad(rows, j, map, step_rad) ? travel_rad : 0.0;
  };
  for (std::size_t k = 1; k < n; ++k) {
    if (map.request_timeout_s > 0.0 && core::to_seconds(rows[k].sample.t_ns - rows[k - 1].sample.t_ns) >= asked_again_s) {
      unknown_read(k);
    }
    if (k >= 2 && k + 1 < n && excess(k) * excess(k + 1) < 0.0) unknown_read(k);
  }
  return u;
}

/// The count against the speed over the whole log: a window's count moves at most window_count_allowance_rad, so the
/// count summed over the windows whose times are known cannot exceed those allowances summed —
/// unless the time column's windows are shorter than the drive's: a time in seconds read as ms makes them 1000 times
/// so (docs/drive-log.md, "A count against the speed").
void check_count_against_speed(const std::vector<PreviousRowRead>& rows, const LogMap& map, const UnknownTiming& unknown,
                               double step_rad, const MappedLogReader& reader) {
  double counted_rad = 0.0, allowed_rad = 0.0, integrated_rad = 0.0;
  std::size_t windows = 0;
  for (std::size_t j = 2; j < rows.size(); ++j) {
    if (unknown.window[j]) continue;
    const PreviousRowRead& a = rows[j - 1];
    const PreviousRowRead& b = rows[j];
    counted_rad += std::abs(b.travel_el_rad - a.travel_el_rad);
    allowed_rad += window_count_allowance_rad(rows, j, map, step_rad);
    integrated_rad += 0.5 * (std::abs(a.omega_at_read_rad_s) + std::abs(b.omega_at_read_rad_s)) *
                      core::to_seconds(b.sample.t_ns - a.sample.t_ns);
    ++windows;
  }
  if (!(counted_rad > allowed_rad)) return;
  std::ostringstream why;
  why << std::setprecision(4) << "over the " << windows << " windows whose times are known the drive's count moved "
      << counted_rad << " rad, more than the speed column allows in the time column's windows (" << allowed_rad
      << " rad at most: each window's faster read over its time, the PLL's lead and two count steps); the speeds over "
         "those times integrate to "
      << integrated_rad << " rad, "
      << (integrated_rad > 0.0 ? counted_rad / integrated_rad : std::numeric_limits<double>::infinity())
      << " times less than counted. The time column is likely in another unit than the log's map says (its `unit:`: "
         "a column in seconds read as ms is a factor of 1000), or the count's unit is not the drive's";
  reader.fail_at(rows.front().line, Quantity::kTravelEl, why.str());
}

/// The change of the PLL's mean acceleration at each read j, over reads j − 2, j − 1, j (core::read_accel_change_rad_s2);
/// NaN where either window is unknown, or at the first two reads.
std::vector<double> accel_changes(const std::vector<PreviousRowRead>& rows, const UnknownTiming& unknown) {
  std::vector<double> out(rows.size(), std::nan(""));
  const auto read_at = [&](std::size_t j) { return core::SpeedRead{rows[j].sample.t_ns, rows[j].omega_at_read_rad_s}; };
  for (std::size_t j = 2; j < rows.size(); ++j) {
    if (!unknown.window[j - 1] && !unknown.window[j])
      out[j] = core::read_accel_change_rad_s2(read_at(j - 2), read_at(j - 1), read_at(j));
  }
  return out;
}

/// A window's speed rebuilt from a tracker's reads (core::window_mean_speed_rad_s) is held to the absolute bound a cell
/// is held to: reads too close for the log's clock, or a column that is not a speed, extrapolate beyond any drive's.
/// Within it, a rebuilt speed off beyond the machine's plausible one carries the error its reads show and is judged
/// transient there (docs/drive-log.md, "Speed at the read"); a reader's machine bound would refuse a whole real log
/// for one jittery pair of tied reads.
void check_rebuilt_speed(const MappedLogReader& reader, const PreviousRowRead& previous, const PreviousRowRead& row,
                         const core::AveragedSample& s) {
  static const Bound bound = DriveLogLimits{}.speed_rad_s;
  if (std::abs(s.omega_el_rad_s) <= bound.max_abs) return;
  std::ostringstream why;
  why << std::setprecision(6) << "the window's mean speed rebuilt from the tracker's speeds at this read and at line "
      << previous.line << " (" << previous.omega_at_read_rad_s << " and " << row.omega_at_read_rad_s << " rad/s, "
      << 1e3 * core::to_seconds(row.sample.t_ns - previous.sample.t_ns) << " ms apart) is " << s.omega_el_rad_s
      << " rad/s, beyond the plausible ±" << bound.max_abs << " rad/s (" << bound.why
      << "): reads this close or this far apart in speed give the tracker no slope (docs/drive-log.md, \"Speed at "
         "the read\")";
  reader.fail_at(row.line, Quantity::kOmegaEl, why.str());
}

/// The samples of a previous_row log's rows (rows not empty): each window from the read before it, its speed rebuilt
/// where the column is a PLL's, its count where the log has one; the windows next to a read whose time is unknown
/// left out, and counted in `read`.
void previous_row_samples(const std::vector<PreviousRowRead>& rows, const LogMap& map, bool counted,
                          const MappedLogReader& reader, std::vector<core::AveragedSample>& out, AveragedLogRead& read) {
  // The counts at the reads whose times are known, and the read that ends each sample: the counted speeds.
  std::vector<core::CountRead> reads;
  std::vector<std::size_t> read_ending;
  std::vector<core::CountRead> all_reads;
  all_reads.reserve(rows.size());
  for (const PreviousRowRead& row : rows) all_reads.push_back({row.sample.t_ns, row.travel_el_rad});
  const double step_rad = counted ? count_step_rad(all_reads) : 0.0;
  const UnknownTiming unknown = unknown_timing(rows, map, step_rad);
  if (counted && step_rad > 0.0) check_count_against_speed(rows, map, unknown, step_rad, reader);
  const std::vector<double> accel_change = map.speed_pll.given() ? accel_changes(rows, unknown) : std::vector<double>{};
  read.opening_rows = 1;
  bool after_unknown = false;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (counted && !unknown.read[k]) reads.push_back(all_reads[k]);
    if (unknown.window[k]) {
      if (k > 0) ++read.unknown_windows;
      after_unknown = k > 0;
      continue;
    }
    core::AveragedSample s = rows[k].sample;
    const PreviousRowRead& previous = rows[k - 1];
    s.t_start_ns = previous.sample.t_ns;
    s.gap_before = after_unknown;
    after_unknown = false;
    if (map.speed_pll.given()) {
      // A PLL's speed at each read: the window's mean from this read's and the previous one's (§13), its error from
      // the larger change of acceleration the reads show at the window's two ends (a change inside the window shows
      // in the PLL's speed by the next read, not yet at this one), and that error's noise from the changes around it.
      const core::SpeedRead read_before{previous.sample.t_ns, previous.omega_at_read_rad_s},
          read_now{s.t_ns, rows[k].omega_at_read_rad_s};
      s.omega_el_rad_s = core::window_mean_speed_rad_s(read_before, read_now, s.t_start_ns, map.speed_pll.ramp_lag_s());
      check_rebuilt_speed(reader, previous, rows[k], s);
      s.omega_el_at_reads_max_rad_s = core::reads_speed_max_rad_s(read_before, read_now);
      const double h_s = core::to_seconds(s.t_ns - s.t_start_ns);
      const double after = k + 1 < rows.size() ? accel_change[k + 1] : std::nan("");
      const double change = std::fmax(std::fabs(accel_change[k]), std::fabs(after));  // fmax: a NaN side left out
      if (std::isfinite(change)) s.omega_el_error_rad_s = core::window_mean_speed_error_rad_s(map.speed_pll, change, h_s);
      std::array<double, core::kAccelChangeRunReads> run;
      run.fill(std::nan(""));
      const std::size_t half = core::kAccelChangeRunReads / 2, first = k > half ? k - half : 0;
      for (std::size_t j = first; j < rows.size() && j - first < run.size(); ++j) run[j - first] = accel_change[j];
      s.omega_el_error_noise_rad_s =
          core::window_mean_speed_error_rad_s(map.speed_pll, core::accel_change_sigma_rad_s2(run), h_s);
    }
    if (counted) read_ending.push_back(reads.size() - 1);
    out.push_back(s);
    keep_extras(rows[k], &previous, read);
  }
  if (counted) set_counted_speeds(out, reads, read_ending, step_rad);
}

/// The median window against one control period (DriveLogLimits::control_period_s): a window holds at least one
/// cycle, and its two stamps, each within half a cycle of the read, still make it at least half of one.
void check_window_lengths(const std::string& path, std::size_t first_line, const std::vector<core::AveragedSample>& out,
                          double control_period_s) {
  if (!(control_period_s > 0.0)) return;
  std::vector<std::int64_t> lengths;
  lengths.reserve(out.size());
  for (const core::AveragedSample& s : out) lengths.push_back(s.t_ns - s.t_start_ns);
  const auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), mid, lengths.end());
  const double median_s = core::to_seconds(*mid);
  if (median_s >= 0.5 * control_period_s) return;
  char text[400];
  std::snprintf(text, sizeof text,
                "the windows are %.3g µs long (the median of %zu), shorter than half a control period (%.3g µs, "
                "estimator.averaged.control_period_s), though each mean holds whole control cycles: the time column is "
                "likely in another unit than the log's map says (its `unit:`), or the configuration is another drive's",
                median_s * 1e6, out.size(), control_period_s * 1e6);
  throw DriveLogError(path, first_line, 0, "column t", text);
}

}  // namespace

std::vector<core::AveragedSample> read_averaged_log(const std::string& path, const LogMap& map, const DriveLogLimits& limits,
                                                    AveragedLogRead* read_out) {
  if (!map.averaged()) {
    throw ConfigError(map.name, 0, 0, "samples", "a map of instantaneous samples does not give averaged samples");
  }
  MappedLogReader reader(path, map, limits);
  if (map.columns_optional && map.window == Window::kStartColumn && !reader.has(Quantity::kTStart)) {
    reader.fail_header({"t_start", "required"});
  }
  // Our own format names its quantities in the header, a map's optional columns may be absent from it: what an
  // averaged log needs is checked against what the header has.
  if (const std::optional<LayoutProblem> p = averaged_log_layout_problem(reader.present())) reader.fail_header(*p);
  AveragedLogRead read;
  read.layout.u_dc = reader.has(Quantity::kUDc);
  read.layout.t_winding = reader.has(Quantity::kTWinding);
  read.layout.t_magnet = reader.has(Quantity::kTMagnet);
  read.layout.t_drive = reader.has(Quantity::kTDrive);
  read.layout.t_coolant = reader.has(Quantity::kTCoolant);
  read.layout.u_dq = reader.has(Quantity::kUD);
  read.layout.i_dq = reader.has(Quantity::kID);
  read.layout.duty = reader.has(Quantity::kDuty);
  read.layout.i_motor = reader.has(Quantity::kIMotor);

  // Every row as read; a previous_row log's windows (and the speeds rebuilt over them) once all are in.
  const bool counted = reader.has(Quantity::kTravelEl);
  std::vector<PreviousRowRead> rows;
  std::vector<core::CountRead> start_column_reads;  // window: t_start: the count at each row's read
  std::vector<std::size_t> start_column_ends;
  std::vector<core::AveragedSample> out;
  MappedRow r;
  std::size_t first_line = 0;
  while (reader.next(r)) {
    if (read.rows++ == 0) first_line = r.line;
    PreviousRowRead row;
    core::AveragedSample& s = row.sample;
    s.t_ns = r.t_ns;
    s.i_dq_A = {r[Quantity::kID], r[Quantity::kIQ]};
    s.u_dq_V = {r[Quantity::kUD], r[Quantity::kUQ]};
    s.omega_el_rad_s = r[Quantity::kOmegaEl];
    s.u_dc_V = r[Quantity::kUDc];
    s.t_winding_C = r[Quantity::kTWinding];
    s.t_magnet_C = r[Quantity::kTMagnet];
    s.t_drive_C = r[Quantity::kTDrive];
    s.t_coolant_C = r[Quantity::kTCoolant];
    row.duty = r[Quantity::kDuty];
    row.i_motor_A = r[Quantity::kIMotor];
    row.line = r.line;
    if (map.window == Window::kStartColumn) {
      s.t_start_ns = std::llround(r[Quantity::kTStart] * 1e9);
      if (s.t_start_ns > s.t_ns) reader.fail_at(r.line, Quantity::kTStart, "window starts after it ends (t_start > t)");
      if (counted) {
        start_column_ends.push_back(start_column_reads.size());
        start_column_reads.push_back({r.t_ns, r[Quantity::kTravelEl]});
      }
      out.push_back(s);
      keep_extras(row, nullptr, read);
      continue;
    }
    row.omega_at_read_rad_s = r[Quantity::kOmegaEl];
    if (counted) row.travel_el_rad = r[Quantity::kTravelEl];
    rows.push_back(row);
  }

  if (!rows.empty()) previous_row_samples(rows, map, counted, reader, out, read);
  if (counted && map.window == Window::kStartColumn) {
    set_counted_speeds(out, start_column_reads, start_column_ends, count_step_rad(start_column_reads));
  }
  if (out.empty()) {
    throw DriveLogError(path, first_line, 0, "",
                        read.unknown_windows > 0
                            ? "no samples: every window is unknown (the first row's began before the log; the others "
                              "follow a read whose time is unknown: see docs/drive-log.md, \"Rows stamped late\")"
                            : "no samples: the only row holds means since a read before the log began (an unknown "
                              "window); a sample needs the row before it");
  }
  check_window_lengths(path, first_line, out, limits.control_period_s);
  read.repairs = reader.repairs();
  if (read_out) *read_out = read;
  return out;
}

AveragedLogWriter::AveragedLogWriter(const std::string& path, const AveragedLogLayout& layout)
    : out_(path, std::ios::binary | std::ios::trunc), layout_(layout) {
  if (!out_) throw InputError(path, 0, 0, "", "cannot create file");  // an output: not the data's fault
  std::string h = "t,t_start,i_d,i_q,u_d,u_q,omega_el";
  if (layout_.u_dc) h += ",u_dc";
  if (layout_.t_winding) h += ",T_winding";
  if (layout_.t_magnet) h += ",T_magnet";
  if (layout_.t_drive) h += ",T_drive";
  if (layout_.t_coolant) h += ",T_coolant";
  out_ << h << '\n';
}

void AveragedLogWriter::write(const core::AveragedSample& s) {
  line_.clear();
  append_number(line_, core::to_seconds(s.t_ns));
  append_number(line_ += ',', core::to_seconds(s.t_start_ns));
  for (double v : {s.i_dq_A[0], s.i_dq_A[1], s.u_dq_V[0], s.u_dq_V[1], s.omega_el_rad_s}) append_number(line_ += ',', v);
  if (layout_.u_dc) append_number(line_ += ',', s.u_dc_V);
  if (layout_.t_winding) append_number(line_ += ',', s.t_winding_C);
  if (layout_.t_magnet) append_number(line_ += ',', s.t_magnet_C);
  if (layout_.t_drive) append_number(line_ += ',', s.t_drive_C);
  if (layout_.t_coolant) append_number(line_ += ',', s.t_coolant_C);
  line_ += '\n';
  out_ << line_;
}

void AveragedLogWriter::flush() { out_.flush(); }

DriveLogRow to_drive_log_row(const core::AveragedSample& s) {
  DriveLogRow r;
  r.sample.t_ns = s.t_ns;
  r.sample.theta_el_rad = 0.0;
  r.sample.omega_el_rad_s = s.omega_el_rad_s;
  r.sample.u_dc_V = std::isnan(s.u_dc_V) ? 0.0 : s.u_dc_V;
  r.sample.voltage_frame = core::Frame::kDq;
  r.sample.u_V = {s.u_dq_V[0], s.u_dq_V[1], 0.0};
  r.sample.current_frame = core::Frame::kDq;
  r.sample.i_A = {s.i_dq_A[0], s.i_dq_A[1], 0.0};
  r.sample.gap_before = s.gap_before;
  r.sample.t_winding_C = s.t_winding_C;
  if (!std::isnan(s.t_magnet_C)) r.t_magnet_C = s.t_magnet_C;
  r.sample.t_coolant_C = s.t_coolant_C;
  return r;
}

DriveLogLayout rotor_frame_layout(const AveragedLogLayout& layout) {
  DriveLogLayout l;
  l.angle = false;
  l.u_dc = layout.u_dc;
  l.voltage_abc = l.current_abc = false;
  l.voltage_dq = l.current_dq = true;
  l.t_winding = layout.t_winding;
  l.t_magnet = layout.t_magnet;
  l.t_coolant = layout.t_coolant;
  return l;
}

void check_voltages_recorded(const std::vector<core::AveragedSample>& samples, const core::MachineSi& machine,
                             const std::string& log_path) {
  double emf_V = 0.0, emf_at_s = 0.0, current_A = 0.0;
  for (const core::AveragedSample& s : samples) {
    if (s.u_dq_V.x() != 0.0 || s.u_dq_V.y() != 0.0) return;
    if (const double e = std::abs(s.omega_el_rad_s) * machine.psi_m_Wb; e > emf_V) {
      emf_V = e;
      emf_at_s = core::to_seconds(s.t_ns);
    }
    current_A = std::max(current_A, s.i_dq_A.norm());
  }
  if (!(emf_V > 0.0 || current_A > 0.0)) return;
  char implied[240];
  if (emf_V > 0.0) {
    std::snprintf(implied, sizeof implied,
                  "while the machine's turning implies a back EMF of up to %.4g V (|omega| x the configured psi_m %.4g "
                  "Wb, at t = %.6g s) and the current reaches %.4g A",
                  emf_V, machine.psi_m_Wb, emf_at_s, current_A);
  } else {  // at rest throughout: only the resistive drop
    std::snprintf(implied, sizeof implied,
                  "while the machine stood still and the current reaches %.4g A, a drop of %.4g V across the configured "
                  "r_s %.4g Ohm",
                  current_A, current_A * machine.r_s_Ohm, machine.r_s_Ohm);
  }
  char text[760];
  std::snprintf(text, sizeof text,
                "exactly 0 in every one of the %zu samples, %s: the log carries no voltages (a logger that writes zeros "
                "for values it does not read, a bridge off throughout whose logger writes zeros then, or voltages below "
                "the column's resolution throughout; docs/drive-log.md, \"Errors\"), and nothing in it can be estimated "
                "or diagnosed",
                samples.size(), implied);
  throw DriveLogError(log_path, 0, 0, "columns u_d, u_q", text);
}

void check_averaged_supports(const MachineConfig& c, const std::string& config_name, bool has_u_dc,
                             const std::string& log_path) {
  const core::ModelExtensions& x = c.estimator.extensions;
  if (!x.current_offset_A.isZero(0.0) || !x.current_gain_error.isZero(0.0)) {
    throw ConfigError(config_name, 0, 0, "model_extensions.current_offset/current_gain",
                      "per-phase current offsets and gains have no rotor-frame mean, so averaged samples (" + log_path +
                          ") cannot be corrected for them; remove them for this source");
  }
  check_log_supports(c, config_name, has_u_dc, log_path);
}

}  // namespace rpem::io
