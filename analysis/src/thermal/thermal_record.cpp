#include "rpem/analysis/thermal/thermal_record.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/io/averaged_log.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/rotor_frame_rebuild.hpp"

namespace rpem::analysis {
namespace {

using core::kNaN;

/// Feeds one sample to the observer and keeps a completed step.
class Recorder {
 public:
  Recorder(ThermalRecord& r, const io::MachineConfig& m, const io::ThermalConfig& t, const core::PerUnitBase& base)
      : record_(r), observer_(t.fusion.observer, base, m.machine, t.fusion.filter.network.base, t.fusion.coolant_C) {}
  void add(const core::Estimate& e, std::int64_t t_ns, double coolant_C, double winding_C) {
    record_.counts.add(e);
    core::ThermalSample s;
    s.dt_s = previous_ns_ ? 1e-9 * static_cast<double>(t_ns - *previous_ns_) : 0.0;
    s.coolant_C = coolant_C;
    s.winding_sensor_C = winding_C;
    coolant_read_ = coolant_read_ || std::isfinite(coolant_C);
    previous_ns_ = t_ns;
    if (!observer_.add(e, s)) return;
    record_.steps.push_back(observer_.step());
    record_.t_s.push_back(1e-9 * static_cast<double>(observer_.step().t_ns));
  }
  /// A sample carried a coolant reading: a T_coolant column with none (a recording of a drive without the
  /// sensor, docs/drive-log.md) is no coolant.
  [[nodiscard]] bool coolant_read() const noexcept { return coolant_read_; }

 private:
  ThermalRecord& record_;
  core::ThermalObserver observer_;
  std::optional<std::int64_t> previous_ns_;
  bool coolant_read_ = false;
};

}  // namespace

bool ThermalRecord::starts_session(std::size_t k) const {
  return std::binary_search(session_first_step.begin(), session_first_step.end(), k);
}

ThermalRecord join_sessions(std::vector<ThermalRecord> sessions, const std::string& name) {
  if (sessions.empty()) throw std::invalid_argument("join_sessions: no session");
  ThermalRecord out;
  out.log = name;
  out.session_first_step.clear();
  out.coolant = true;
  out.averaged = true;
  for (ThermalRecord& s : sessions) {
    if (s.steps.empty()) throw std::invalid_argument("join_sessions: " + s.log + " has no step of the thermal filter");
    assert(s.session_first_step.size() == 1);  // a session is one log
    // One step after the session before: the session's first step keeps its own length.
    const double shift_s = out.t_s.empty() ? 0.0 : out.t_s.back() + s.steps.front().load.dt_s - s.t_s.front();
    out.session_first_step.push_back(out.steps.size());
    out.session_logs.push_back(s.log);
    out.session_coolant.push_back(s.coolant);
    out.steps.insert(out.steps.end(), s.steps.begin(), s.steps.end());
    for (double t : s.t_s) out.t_s.push_back(t + shift_s);
    out.winding_sensor = out.winding_sensor || s.winding_sensor;
    out.coolant = out.coolant && s.coolant;
    out.averaged = out.averaged && s.averaged;
    out.read_as += (out.read_as.empty() ? "" : "; ") + s.read_as;
  }
  return out;
}

ThermalRecord record_thermal(const io::LogSource& source, const io::MachineConfig& machine,
                             const io::ThermalConfig& thermal) {
  ThermalRecord r;
  r.log = source.path;
  r.session_logs = {source.path};
  const io::DriveLogLimits limits = io::log_limits(machine);
  if (source.averaged()) {
    r.averaged = true;
    r.counts.averaged = true;
    io::AveragedLogRead read;
    std::vector<core::AveragedSample> samples = io::read_averaged_log(source.path, source.map, limits, &read);
    io::check_averaged_supports(machine, "configuration", read.layout.u_dc, source.path);
    const io::RotorFrameRebuild rebuilt =
        io::complete_rotor_frame(samples, read, machine.machine, io::command_hold_s(machine.estimator), source.path);
    r.winding_sensor = read.layout.t_winding;
    r.read_as = io::describe(source, read) + (rebuilt.any() ? "; " + rebuilt.describe() : "");
    core::AveragedDriveEstimator estimator(machine.machine, io::estimator_settings(machine, rebuilt));
    Recorder rec(r, machine, thermal, estimator.base());
    for (const core::AveragedSample& s : samples) rec.add(estimator.step(s), s.t_ns, s.t_coolant_C, s.t_winding_C);
    r.coolant = read.layout.t_coolant && rec.coolant_read();
    r.session_coolant = {r.coolant};
    return r;
  }
  io::DriveLogReader reader(source.path, source.map, limits);
  io::check_log_supports(machine, "configuration", reader.layout().u_dc, source.path);
  r.winding_sensor = reader.layout().t_winding;
  core::DriveEstimator estimator(machine.machine, machine.estimator);
  Recorder rec(r, machine, thermal, estimator.base());
  io::DriveLogRow row;
  while (reader.next(row)) {
    rec.add(estimator.step(row.sample), row.sample.t_ns, row.sample.t_coolant_C, row.sample.t_winding_C);
  }
  r.coolant = reader.layout().t_coolant && rec.coolant_read();
  r.session_coolant = {r.coolant};
  r.read_as = source.path + " as " + source.format + io::describe(reader.reader().repairs());
  return r;
}

}  // namespace rpem::analysis
