#include "rpem/io/rotor_frame_rebuild.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "rpem/core/clock.hpp"
#include "rpem/core/settings.hpp"
#include "rpem/core/sinc.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::io {
namespace {

bool all_zero(const std::vector<core::AveragedSample>& samples, core::Vec2 core::AveragedSample::*v) {
  return std::all_of(samples.begin(), samples.end(), [&](const core::AveragedSample& s) { return (s.*v).isZero(0.0); });
}

bool any_nonzero(const std::vector<double>& values) {
  return std::any_of(values.begin(), values.end(), [](double v) { return v != 0.0; });
}

/// VESC's SIGN(): −1 below 0, +1 otherwise (utils_math.h), as the firmware signs duty_now and the motor current.
double sign(double v) { return v < 0.0 ? -1.0 : 1.0; }

}  // namespace

std::string RotorFrameRebuild::describe() const {
  if (!voltages && !currents) return "";
  std::string s = "the log has no d/q ";
  s += voltages && currents ? "values" : voltages ? "voltages" : "currents";
  s += ": ";
  if (currents) s += "i_d = 0, i_q = sign(duty)·i_motor";
  if (voltages) {
    s += currents ? "; " : "";
    s += "u_d, u_q rebuilt from |u| = |duty|·u_dc/√3 in steady state (u_d = R_s·i_d − ω·L_q·i_q of the configuration), "
         "applied rotor-frame means: no angle-lock test on them";
  }
  if (short_magnitude > 0) {
    char text[160];
    std::snprintf(text, sizeof text, "; %llu samples with |u| below the model's |u_d| (u_q = 0 there)",
                  static_cast<unsigned long long>(short_magnitude));
    s += text;
  }
  return s + " (docs/drive-log.md, \"Logs without d/q values\")";
}

RotorFrameRebuild complete_rotor_frame(std::vector<core::AveragedSample>& samples, const AveragedLogRead& read,
                                       const core::MachineSi& machine, double command_hold_s, const std::string& log_path) {
  RotorFrameRebuild r;
  const bool duty = read.layout.duty && read.duty.size() == samples.size();
  const bool motor = read.layout.i_motor && read.i_motor_A.size() == samples.size();
  r.voltages = duty && read.layout.u_dc &&
               (!read.layout.u_dq || (all_zero(samples, &core::AveragedSample::u_dq_V) && any_nonzero(read.duty)));
  r.currents =
      motor && (!read.layout.i_dq || (all_zero(samples, &core::AveragedSample::i_dq_A) && any_nonzero(read.i_motor_A)));
  if (!r.voltages) check_voltages_recorded(samples, machine, log_path);
  if (!r.voltages && !r.currents) return r;

  for (std::size_t k = 0; k < samples.size(); ++k) {
    core::AveragedSample& s = samples[k];
    const double sigma = sign(duty ? read.duty[k] : s.u_dq_V.y());
    if (r.currents) s.i_dq_A = {0.0, sigma * read.i_motor_A[k]};
    if (!r.voltages) continue;
    if (std::isnan(s.u_dc_V)) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "the window ending at t = %.6g s has no DC-link voltage, from which its duty cycle's voltage is "
                    "rebuilt (docs/drive-log.md, \"Logs without d/q values\")",
                    core::to_seconds(s.t_ns));
      throw DriveLogError(log_path, 0, 0, "column u_dc", text);
    }
    const double w = s.omega_el_rad_s;
    // A command held for T_c turning at ω averages to sinc(ω·T_c/2) of its length (docs/derivations.md §11).
    const double half = 0.5 * w * command_hold_s;
    const double sinc = core::sinc(half);
    // The duty is read at the window's end, the currents and speed are its means: where the duty at the window's
    // start is known, the mean of the two is the window's (exact for a linear change; docs/derivations.md §13).
    const double end_V = std::abs(read.duty[k]) * s.u_dc_V;
    const double start_V = std::abs(read.duty_at_start[k]) * read.u_dc_at_start_V[k];
    const double mean_V = std::isfinite(start_V) ? 0.5 * (start_V + end_V) : end_V;
    const double magnitude_V = sinc * mean_V / std::numbers::sqrt3;
    double u_d = machine.r_s_Ohm * s.i_dq_A.x() - w * machine.l_q_H * s.i_dq_A.y();
    if (std::abs(u_d) > magnitude_V) {
      u_d = std::copysign(magnitude_V, u_d);
      ++r.short_magnitude;
    }
    s.u_dq_V = {u_d, sigma * std::sqrt(std::max(magnitude_V * magnitude_V - u_d * u_d, 0.0))};
  }
  return r;
}

double command_hold_s(const core::EstimatorSettings& s) noexcept {
  return s.averaged.voltage_is_command && s.averaged.control_period_s > 0.0 ? s.averaged.control_period_s : 0.0;
}

core::EstimatorSettings estimator_settings(const MachineConfig& config, const RotorFrameRebuild& rebuilt) {
  return rebuilt.voltages ? core::for_applied_voltages(config.estimator) : config.estimator;
}

}  // namespace rpem::io
