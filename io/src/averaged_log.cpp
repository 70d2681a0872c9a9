#include "rpem/io/averaged_log.hpp"

#include <cmath>
#include <vector>

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
                        const std::vector<std::size_t>& ends) {
  const double step_rad = count_step_rad(reads);
  const auto side_max_ns = static_cast<std::int64_t>(core::kCountRunSideMaxS * 1e9);
  for (std::size_t k = 0; k < out.size(); ++k) {
    const std::size_t e = ends[k];
    if (e == 0 || reads[e - 1].t_ns != out[k].t_start_ns) continue;
    out[k].omega_counted_el_rad_s = core::grown_count_speed_rad_s(reads, e - 1, e, step_rad, side_max_ns);
  }
}

}  // namespace

std::vector<core::AveragedSample> read_averaged_log(const std::string& path, const LogMap& map, const DriveLogLimits& limits,
                                                    AveragedLogRead* read_out) {
  if (!map.averaged()) {
    throw ConfigError(map.name, 0, 0, "samples", "a map of instantaneous samples does not give averaged samples");
  }
  MappedLogReader reader(path, map, limits);
  if (map.columns_optional) {
    // Our own format names its quantities in the header: what an averaged log needs is checked here.
    if (map.window == Window::kStartColumn && !reader.has(Quantity::kTStart)) {
      reader.fail_at(reader.line(), "t_start", "required column is missing from the header");
    }
    if (const std::optional<LayoutProblem> p = averaged_log_layout_problem(reader.present())) {
      reader.fail_at(reader.line(), p->column,
                     p->reason == "required" ? "required column is missing from the header" : p->reason);
    }
  }
  AveragedLogRead read;
  read.layout.u_dc = reader.has(Quantity::kUDc);
  read.layout.t_winding = reader.has(Quantity::kTWinding);
  read.layout.t_magnet = reader.has(Quantity::kTMagnet);
  read.layout.t_drive = reader.has(Quantity::kTDrive);
  read.layout.t_coolant = reader.has(Quantity::kTCoolant);

  std::vector<core::AveragedSample> out;
  MappedRow r;
  std::optional<std::int64_t> previous_t_ns;
  double previous_omega_rad_s = 0.0;  // the previous row's speed as the column gives it
  // The drive's count of its angle (travel_el) at every row's read, and the read that ends each sample: the
  // counted speeds, after the rows.
  const bool counted = reader.has(Quantity::kTravelEl);
  std::vector<core::CountRead> reads;
  std::vector<std::size_t> read_ending;
  std::size_t first_line = 0;
  while (reader.next(r)) {
    ++read.rows;
    core::AveragedSample s;
    s.t_ns = r.t_ns;
    if (map.window == Window::kStartColumn) {
      s.t_start_ns = std::llround(r[Quantity::kTStart] * 1e9);
      if (s.t_start_ns > s.t_ns) reader.fail_at(r.line, Quantity::kTStart, "window starts after it ends (t_start > t)");
    } else if (!previous_t_ns) {
      // The means of the first row ran since a read before the log began: an unknown window.
      previous_t_ns = r.t_ns;
      previous_omega_rad_s = r[Quantity::kOmegaEl];
      if (counted) reads.push_back({r.t_ns, r[Quantity::kTravelEl]});
      first_line = r.line;
      ++read.opening_rows;
      continue;
    } else {
      s.t_start_ns = *previous_t_ns;
    }
    s.i_dq_A = {r[Quantity::kID], r[Quantity::kIQ]};
    s.u_dq_V = {r[Quantity::kUD], r[Quantity::kUQ]};
    s.omega_el_rad_s = r[Quantity::kOmegaEl];
    if (map.speed_lag_s > 0.0) {
      // A PLL's speed at each read: the window's mean from this read's and the previous one's (§13).
      s.omega_el_rad_s = core::window_mean_speed_rad_s({*previous_t_ns, previous_omega_rad_s}, {r.t_ns, s.omega_el_rad_s},
                                                       s.t_start_ns, map.speed_lag_s);
    }
    previous_t_ns = r.t_ns;
    previous_omega_rad_s = r[Quantity::kOmegaEl];
    s.u_dc_V = r[Quantity::kUDc];
    s.t_winding_C = r[Quantity::kTWinding];
    s.t_magnet_C = r[Quantity::kTMagnet];
    s.t_drive_C = r[Quantity::kTDrive];
    s.t_coolant_C = r[Quantity::kTCoolant];
    if (counted) {
      read_ending.push_back(reads.size());
      reads.push_back({r.t_ns, r[Quantity::kTravelEl]});
    }
    out.push_back(s);
  }
  if (counted) set_counted_speeds(out, reads, read_ending);
  if (out.empty()) {
    throw DriveLogError(path, first_line, 0, "",
                        "no samples: the only row holds means since a read before the log began (an unknown window); "
                        "a sample needs the row before it");
  }
  read.repairs = reader.repairs();
  if (read_out) *read_out = read;
  return out;
}

AveragedLogWriter::AveragedLogWriter(const std::string& path, const AveragedLogLayout& layout)
    : out_(path, std::ios::binary | std::ios::trunc), layout_(layout) {
  if (!out_) throw DriveLogError(path, 0, 0, "", "cannot create file");
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
  if (!std::isnan(s.t_winding_C)) r.t_winding_C = s.t_winding_C;
  if (!std::isnan(s.t_magnet_C)) r.t_magnet_C = s.t_magnet_C;
  if (!std::isnan(s.t_coolant_C)) r.t_coolant_C = s.t_coolant_C;
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
