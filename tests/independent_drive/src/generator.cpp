#include "indep_drive/generator.hpp"

#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>

#include "indep_drive/controller.hpp"
#include "indep_drive/flux_map.hpp"
#include "indep_drive/integrator.hpp"
#include "indep_drive/random_streams.hpp"
#include "indep_drive/sensors.hpp"
#include "truth_builder.hpp"

namespace indep {

namespace {

MachineParams draw_machine(const Case& c) {
  std::mt19937_64 rng = stream_rng(c.seed, Stream::machine);
  auto draw = [&rng](double span, const std::optional<double>& fixed) {
    const double u = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);  // drawn always: streams stay aligned
    return 1.0 + (fixed ? *fixed : span * u);
  };
  const MachineParams& cfg = c.machine.params;
  MachineParams t = cfg;
  t.psi_m_Wb = cfg.psi_m_Wb * draw(c.draw.psi_m_span_rel, c.draw.psi_m_rel);
  t.r_s_Ohm = cfg.r_s_Ohm * draw(c.draw.r_s_span_rel, c.draw.r_s_rel);
  t.l_d_H = cfg.l_d_H * draw(c.draw.l_span_rel, c.draw.l_d_rel);
  t.l_q_H = cfg.l_q_H * draw(c.draw.l_span_rel, c.draw.l_q_rel);
  if (!(t.psi_m_Wb > 0.0 && t.r_s_Ohm > 0.0 && t.l_d_H > 0.0 && t.l_q_H > 0.0)) {
    throw std::invalid_argument("draw: a true parameter is not positive");
  }
  return t;
}

/// ω, R_s and ψm at t: the dynamometer's speed and the drift laws on the temperature tracks.
struct Drivers {
  const OperatingProfile* profile;
  double rpm_to_el;
  TemperatureTrack winding, magnet;
  MachineParams truth;
  DriftParams rs, psim;
  Operating operator()(double t) const {
    Operating o;
    o.omega_el_rad_s = profile->at(t).speed_rpm * rpm_to_el;
    o.r_s_Ohm = truth.r_s_Ohm * (rs.on ? 1.0 + rs.coeff_per_K * (winding.at(t) - rs.reference_C) : 1.0);
    o.psi_m_Wb = truth.psi_m_Wb * (psim.on ? 1.0 + psim.coeff_per_K * (magnet.at(t) - psim.reference_C) : 1.0);
    return o;
  }
};

HarmonicFlux harmonics_of(const Effects& e) {
  HarmonicFlux h;
  if (e.flux_harmonic_6.on) h.add(e.flux_harmonic_6.pair);
  if (e.flux_harmonic_12.on) h.add(e.flux_harmonic_12.pair);
  return h;
}

SensorErrors sensor_errors_of(const Effects& e) {
  SensorErrors s;
  if (e.current_gain.on) s.gain = e.current_gain.value;
  if (e.current_offset.on) s.offset_A = e.current_offset.value;
  if (e.theta_offset.on) s.logged_minus_true_rad = -e.theta_offset.offset_rad;
  return s;
}

SensorSpec sensor_spec_of(const SensorSettings& s) {
  return {s.current_noise_A, s.adc_bits,          s.adc_full_scale_A,  s.encoder_counts_per_rev, s.u_dc_noise_V,
          s.u_dc_adc_bits,   s.u_dc_full_scale_V, s.omega_noise_rad_s, s.temperature_noise_K};
}

/// Checks that the flux map stays invertible (positive-definite inductance) over every current the drive may ask for.
void check_invertible(const FluxModel& f, double i_max) {
  for (int a = 0; a < 72; ++a) {
    for (double r = 0.1; r <= 1.0001; r += 0.1) {
      const Vec2 i = rotate({r * i_max, 0.0}, a * kPi / 36.0);
      const Inductance2 l = f.inductance(i);
      if (!(l.dd_H > 0.0 && l.qq_H > 0.0 && l.dd_H * l.qq_H > l.dq_H * l.dq_H)) {
        throw std::runtime_error("saturation: the scaled map is not invertible at i = (" + std::to_string(i.x) + ", " +
                                 std::to_string(i.y) + ") A; lower saturation.depth or raise full_scale_current_A");
      }
    }
  }
}

}  // namespace

Result generate(const Case& input) {
  Result r;
  r.resolved = resolve_defaults(input);
  const Case& c = r.resolved;
  const Effects& e = c.effects;
  const MachineParams truth = draw_machine(c);
  const int p = truth.pole_pairs;
  const double t_c = 1.0 / c.control.rate_Hz;
  const double u_dc = c.inverter.u_dc_V;

  FluxModel flux(truth.l_d_H, truth.l_q_H, c.machine.rated_peak_current_A(), {});
  std::optional<FluxMapFit> fit;
  if (e.saturation.any()) {
    fit = fit_flux_map(read_flux_map(e.saturation.map_path), e.saturation.degree);
    if (fit->rms_residual_Wb > 0.01 * std::abs(fit->psi0_Wb)) {
      throw std::runtime_error(e.saturation.map_path + ": the co-energy fit leaves " + std::to_string(fit->rms_residual_Wb) +
                               " Wb rms (over 1 % of the magnet flux): the map is not a symmetric, reciprocal flux map");
    }
    flux = scale_flux_map(*fit, truth, e.saturation.full_scale_current_A,
                          {e.saturation.ld, e.saturation.lq, e.saturation.cross, e.saturation.depth});
    check_invertible(flux, c.control.current_limit_A);
  }
  const DeadTime dead_time{e.deadtime.t_dead_s * c.inverter.switching_frequency_Hz * u_dc + e.deadtime.v_device_V,
                           e.deadtime.i_band_A};
  const Plant plant(flux, harmonics_of(e), e.iron_loss.on ? e.iron_loss.r_fe_Ohm : std::numeric_limits<double>::infinity(),
                    dead_time, e.deadtime.on);

  const OperatingProfile profile =
      c.profile.points.empty() ? default_profile(c.machine, c.duration_s, c.profile.max_speed_pu, c.profile.max_torque_pu)
                               : OperatingProfile(c.profile.points);
  const Drivers drivers{&profile, 2.0 * kPi / 60.0 * p, c.thermal.winding, c.thermal.magnet,
                        truth,    e.rs_drift,           e.psim_drift};

  Sensors sensors(sensor_spec_of(c.sensors), sensor_errors_of(e), p, stream_rng(c.seed, Stream::sensors)());
  ControllerConfig cc;
  cc.model = c.machine.params;
  cc.period_s = t_c;
  cc.bandwidth_rad_s = 2.0 * kPi * c.control.bandwidth_Hz;
  cc.current_limit_A = c.control.current_limit_A;
  cc.angle_advance_periods = c.control.angle_advance_periods;
  cc.modulation = c.inverter.modulation;
  CurrentController controller(cc);
  DelayLine delay(e.delay.on ? e.delay.periods : 0.0);
  std::optional<IntervalAverager> averager;
  if (c.averaged.on) {
    averager.emplace(1.0 / c.averaged.rate_Hz, c.averaged.jitter_rel, c.averaged.min_interval_s, c.averaged.max_interval_s,
                     stream_rng(c.seed, Stream::intervals)());
  }
  const bool plant_average = averager && c.averaged.source == AveragedSource::plant;

  detail::RunFacts facts;
  facts.true_machine = truth;
  facts.fit = fit ? &*fit : nullptr;
  {
    std::mt19937_64 rotor = stream_rng(c.seed, Stream::rotor);
    facts.initial_theta_rad = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(rotor);
  }
  const Operating op0 = drivers(0.0);
  PlantState x;
  x.theta_rad = facts.initial_theta_rad;
  x.psi_Wb = flux.flux({}, op0.psi_m_Wb) + op0.psi_m_Wb * plant.harmonics().value(x.theta_rad);
  std::array<double, 3> legs{};
  PlantEval now = plant.evaluate(x, legs, op0);

  const auto rows = static_cast<std::size_t>(std::llround(c.duration_s * c.control.rate_Hz));
  if (c.keep_log_rows) r.log.reserve(rows);
  if (c.keep_plant_rows) r.plant.reserve(rows);
  auto outputs = [&](const PlantEval& ev, double t) {
    return AveragedSample{ev.i_A.x,
                          ev.i_A.y,
                          ev.u_V.x,
                          ev.u_V.y,
                          drivers(t).omega_el_rad_s,
                          u_dc,
                          c.thermal.winding.at(t),
                          c.thermal.magnet.at(t)};
  };

  for (std::size_t k = 0; k < rows; ++k) {
    const double t = static_cast<double>(k) * t_c;
    const Operating op = drivers(t);
    facts.extremes.update(now.i_m_A);
    const ProfilePoint point = profile.at(t);

    // What the drive measures at t, and the command it issues.
    const std::array<double, 3> i_meas = sensors.currents(now.i_abc_A);
    const double theta_meas = sensors.angle(x.theta_rad);
    const double omega_meas = sensors.omega(op.omega_el_rad_s);
    const double u_dc_meas = sensors.u_dc(u_dc);
    const double t_w = sensors.temperature(c.thermal.winding.at(t));
    const double t_m = sensors.temperature(c.thermal.magnet.at(t));
    const ControllerOutput cmd =
        controller.step(i_meas, theta_meas, omega_meas, u_dc_meas, point.torque_Nm, point.i_d_inject_A);
    if (c.keep_log_rows) {
      r.log.push_back({t, theta_meas, omega_meas, u_dc_meas, cmd.u_abc_V, i_meas, t_w, t_m, point.torque_Nm});
    }
    if (averager && !plant_average) {
      const Vec2 i_dq = park(clarke(i_meas), theta_meas);
      averager->add_sample(t, {i_dq.x, i_dq.y, cmd.u_dq_V.x, cmd.u_dq_V.y, omega_meas, u_dc_meas, t_w, t_m});
    }
    PlantRow row;
    row.t_s = t;
    row.theta_el_rad = wrap_2pi(x.theta_rad);
    row.omega_el_rad_s = op.omega_el_rad_s;
    row.i_A = now.i_A;
    row.psi_m_Wb = op.psi_m_Wb;
    row.r_s_Ohm = op.r_s_Ohm;
    row.torque_Nm = plant.torque_Nm(x, now, op, p);
    row.T_winding_C = c.thermal.winding.at(t);
    row.T_magnet_C = c.thermal.magnet.at(t);
    delay.push(cmd.duty);

    // The plant over [t, t + T_c): the delayed issues, each held, in RK4 sub-steps.
    const double f = delay.fraction();
    struct Segment {
      double t0, t1;
      const std::array<double, 3>* duty;
    };
    Segment segments[2] = {{t, t + f * t_c, &delay.first()}, {t + f * t_c, t + t_c, &delay.second()}};
    Vec2 u_integral, u_integral_ab;
    for (const Segment& s : segments) {
      const double length = s.t1 - s.t0;
      if (!(length > 0.0)) continue;
      for (std::size_t leg = 0; leg < 3; ++leg) legs[leg] = ((*s.duty)[leg] - 0.5) * u_dc;
      const int steps = std::max(1, static_cast<int>(std::lround(c.control.substeps * length / t_c)));
      const double h = length / steps;
      now = plant.evaluate(x, legs, drivers(s.t0));
      for (int j = 0; j < steps; ++j) {
        const double t0 = s.t0 + j * h;
        const double theta_before = x.theta_rad;
        const PlantEval next = rk4_step(plant, x, now, t0, h, legs, drivers);
        u_integral = u_integral + (0.5 * h) * (now.u_V + next.u_V);
        u_integral_ab =
            u_integral_ab + (0.5 * h) * (inverse_park(now.u_V, theta_before) + inverse_park(next.u_V, x.theta_rad));
        if (plant_average) averager->add_segment(t0, outputs(now, t0), t0 + h, outputs(next, t0 + h));
        now = next;
      }
    }
    row.u_applied_V = (1.0 / t_c) * u_integral;
    row.u_applied_ab_V = (1.0 / t_c) * u_integral_ab;
    if (c.keep_plant_rows) r.plant.push_back(row);
  }

  if (averager) {
    r.averaged = averager->rows();
    if (plant_average) {
      // The average of n noisy samples: the sensors' noise divided by √n.
      std::mt19937_64 rng = stream_rng(c.seed, Stream::averaged_noise);
      std::normal_distribution<double> normal(0.0, 1.0);
      for (AveragedRow& a : r.averaged) {
        const double n = std::max(1.0, (a.t_s - a.t_start_s) / t_c);
        a.i_d_A += c.sensors.current_noise_A / std::sqrt(n) * normal(rng);
        a.i_q_A += c.sensors.current_noise_A / std::sqrt(n) * normal(rng);
        a.u_dc_V += c.sensors.u_dc_noise_V / std::sqrt(n) * normal(rng);
      }
    }
  }
  r.truth = detail::build_truth(c, facts);
  return r;
}

}  // namespace indep
