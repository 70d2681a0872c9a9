#include "indep_vesc/generator.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "indep_vesc/hall.hpp"
#include "indep_vesc/poller.hpp"
#include "indep_vesc/random_streams.hpp"
#include "indep_vesc/scenario.hpp"
#include "indep_vesc/values.hpp"

namespace indep::vesc {

namespace {

/// The truth of one firmware window, accumulated cycle by cycle (README "Truth").
struct Window {
  int cycles = 0, modulating = 0, open_loop = 0, hall = 0, hall_interpolated = 0;
  double hall_weight_sum = 0.0;
  double eps_sum = 0.0, eps_max = 0.0;
  double w_sum = 0.0, w_first = 0.0, w_last = 0.0;
  Vec2 i_sum;
  double i2_sum = 0.0;
  Vec2 u_sum, i_time_sum;
  double u_time = 0.0;
  double psi_sum = 0.0, r_sum = 0.0, tw_sum = 0.0, tm_sum = 0.0;

  void add(const IsrOutput& out, double eps, double omega_el, Vec2 i_dq, double psi, double r, double tw, double tm) {
    if (cycles == 0) w_first = omega_el;
    w_last = omega_el;
    ++cycles;
    modulating += out.modulating ? 1 : 0;
    open_loop += out.source == AngleSource::startup || out.source == AngleSource::openloop ? 1 : 0;
    hall += out.hall_weight > 0.0 && out.source != AngleSource::startup ? 1 : 0;
    hall_weight_sum += out.hall_weight;
    hall_interpolated += out.hall_weight > 0.0 && out.hall_interpolating ? 1 : 0;
    eps_sum += eps;
    eps_max = std::max(eps_max, std::fabs(eps));
    w_sum += omega_el;
    i_sum = i_sum + i_dq;
    i2_sum += i_dq.dot(i_dq);
    psi_sum += psi;
    r_sum += r;
    tw_sum += tw;
    tm_sum += tm;
  }

  [[nodiscard]] RowTruth finish(const TruthRules& rules) const {
    RowTruth t;
    t.cycles = cycles;
    if (cycles == 0) {
      t.bridge = "none";
      t.angle = "none";
      return t;
    }
    const double n = cycles;
    t.modulating_fraction = modulating / n;
    t.open_loop_fraction = open_loop / n;
    t.hall_fraction = hall / n;
    t.hall_weight_mean = hall_weight_sum / n;
    t.hall_interpolated_fraction = hall_interpolated / n;
    t.frame_error_mean_rad = eps_sum / n;
    t.frame_error_max_abs_rad = eps_max;
    t.omega_el_mean_rad_s = w_sum / n;
    t.omega_el_start_rad_s = w_first;
    t.omega_el_end_rad_s = w_last;
    t.i_d_mean_A = i_sum.x / n;
    t.i_q_mean_A = i_sum.y / n;
    const double i_mean2 = t.i_d_mean_A * t.i_d_mean_A + t.i_q_mean_A * t.i_q_mean_A;
    t.i_dev_rms_A = std::sqrt(std::max(0.0, i2_sum / n - i_mean2));
    if (u_time > 0.0) {
      t.u_d_mean_V = u_sum.x / u_time;
      t.u_q_mean_V = u_sum.y / u_time;
      t.i_d_avg_A = i_time_sum.x / u_time;
      t.i_q_avg_A = i_time_sum.y / u_time;
    }
    t.psi_m_Wb = psi_sum / n;
    t.r_s_Ohm = r_sum / n;
    t.T_winding_C = tw_sum / n;
    t.T_magnet_C = tm_sum / n;
    t.bridge = modulating == cycles ? "modulating" : modulating == 0 ? "bridge_off" : "mixed";
    t.angle = open_loop == cycles           ? "open_loop"
              : hall == cycles              ? "hall"
              : open_loop == 0 && hall == 0 ? "observer"
                                            : "mixed";
    t.angle_locked = open_loop == 0 && eps_max <= rules.locked_max_frame_error_rad;
    t.psi_m_term_V = std::fabs(t.omega_el_mean_rad_s) * t.psi_m_Wb;
    t.r_s_term_V = t.r_s_Ohm * std::sqrt(i_mean2);
    t.excites_psi_m = t.psi_m_term_V >= rules.excites_psi_m_min_V;
    t.excites_r_s = t.r_s_term_V >= rules.excites_r_s_min_V;
    const double dw = std::fabs(w_last - w_first);
    t.transient =
        dw > rules.transient_speed_rel * std::max(std::fabs(t.omega_el_mean_rad_s), rules.transient_speed_floor_rad_s) ||
        t.i_dev_rms_A > rules.transient_current_rms_A;
    return t;
  }
};

/// An ADC reading of x with Gaussian noise of sigma counts, 12 bits around mid.
double adc(double x, double lsb, double offset_counts, double sigma_counts, double mid, std::mt19937_64& rng,
           std::normal_distribution<double>& normal) {
  const double noise = sigma_counts > 0.0 ? sigma_counts * normal(rng) : 0.0;
  const double counts = std::clamp(std::round(x / lsb + mid + offset_counts + noise), 0.0, 4095.0);
  return (counts - mid) * lsb;
}

}  // namespace

Result generate(const Case& input) {
  Result res;
  res.resolved = resolve_defaults(input);
  const Case& c = res.resolved;
  const MachineParams& mp = c.machine.params;
  res.configured = {mp.psi_m_Wb, mp.r_s_Ohm, mp.l_d_H, mp.l_q_H, mp.pole_pairs};

  // The true machine at the reference temperature.
  std::mt19937_64 machine_rng = stream_rng(c.seed, Stream::machine);
  auto drawn = [&](const std::optional<double>& fixed) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double sign = u(machine_rng) < 0.5 ? -1.0 : 1.0;
    const double magnitude = c.draw.span_min + (c.draw.span_max - c.draw.span_min) * u(machine_rng);
    return fixed.value_or(sign * magnitude);
  };
  const double psi_rel = drawn(c.draw.psi_m_rel), r_rel = drawn(c.draw.r_s_rel);
  res.true_at_reference = {mp.psi_m_Wb * (1.0 + psi_rel), mp.r_s_Ohm * (1.0 + r_rel), mp.l_d_H * (1.0 + c.draw.l_rel),
                           mp.l_q_H * (1.0 + c.draw.l_rel), mp.pole_pairs};
  const MachineValues& tm = res.true_at_reference;
  const Thermal& th = c.thermal;
  auto r_at = [&](double t_w) { return tm.r_s_Ohm * (1.0 + th.r_s_coeff_per_K * (t_w - th.reference_C)); };
  auto psi_at = [&](double t_m) { return tm.psi_m_Wb * (1.0 + th.psi_m_coeff_per_K * (t_m - th.reference_C)); };
  double t_w = th.winding_start_C, t_m = th.magnet_start_C;
  const double i_n = c.machine.rated.current_rms_A;
  const double r_th = th.winding_rise_at_rated_K / (3.0 * tm.r_s_Ohm * i_n * i_n);
  const double c_th = th.winding_tau_s / r_th;

  // The VESC, configured by its own detection on the true machine.
  FirmwareParams fp;
  fp.conf = c.firmware;
  fp.f_zv_Hz = c.firmware.f_zv_Hz;
  fp.dt_s = 2.0 / c.firmware.f_zv_Hz;
  fp.r_Ohm = r_at(t_w) * (1.0 + c.firmware.detect_r_rel);
  fp.l_H = 0.5 * (tm.l_d_H + tm.l_q_H) * (1.0 + c.firmware.detect_l_rel);
  fp.psi_Wb = psi_at(t_m) * (1.0 + c.firmware.detect_psi_rel);
  fp.kp = fp.l_H / c.firmware.current_tc_s;
  fp.ki = fp.r_Ohm / c.firmware.current_tc_s;
  const double hall_offset_rad = c.sensors.hall_offset_deg * kPi / 180.0;
  if (c.firmware.hall) fp.hall_table = detect_hall_table(hall_offset_rad);  // VESC Tool's Hall detection
  res.firmware = fp;
  res.vesc_configuration = {fp.psi_Wb, fp.r_Ohm, fp.l_H, fp.l_H, mp.pole_pairs};
  VescFirmware fw(fp);

  PlantParams pp;
  pp.r_s_Ohm = r_at(t_w);
  pp.psi_m_Wb = psi_at(t_m);
  pp.l_d_H = tm.l_d_H;
  pp.l_q_H = tm.l_q_H;
  pp.pole_pairs = mp.pole_pairs;
  pp.inertia_kgm2 = c.mechanics.inertia_kgm2;
  pp.coulomb_Nm = c.mechanics.coulomb_Nm;
  pp.coulomb_band_rad_s = c.mechanics.coulomb_band_rad_s;
  pp.viscous_Nm_s = c.mechanics.viscous_Nm_s;
  pp.drag_Nm_s2 = c.mechanics.drag_Nm_s2;
  pp.external_Nm = c.mechanics.external_Nm;
  pp.t_dead_s = c.power.t_dead_s;
  pp.f_sw_Hz = 0.5 * c.firmware.f_zv_Hz;
  pp.dead_band_A = c.power.dead_band_A;
  res.plant = pp;
  Plant plant(pp);

  std::mt19937_64 offsets_rng = stream_rng(c.seed, Stream::offsets);
  std::normal_distribution<double> normal(0.0, 1.0);
  PlantState x;
  x.theta_el_rad = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(offsets_rng);
  res.initial_theta_rad = x.theta_el_rad;
  plant.open_phases(x);
  std::array<double, 3> adc_offset{};
  for (double& o : adc_offset) o = c.sensors.current_offset_residual_lsb * normal(offsets_rng);

  const double rated_erpm = c.machine.rated.speed_rpm * mp.pole_pairs;
  const double torque_per_A = 1.5 * mp.pole_pairs * mp.psi_m_Wb;  // the configured machine's
  App app(!c.scenario.empty() ? c.scenario
          : c.firmware.hall
              ? builtin_hall_scenario(c.duration_s, c.firmware.l_current_max_A, torque_per_A, mp.pole_pairs, c.seed)
              : builtin_scenario(c.duration_s, c.firmware.l_current_max_A, rated_erpm, 0.9 * c.mechanics.coulomb_Nm,
                                 torque_per_A, c.seed));
  const std::vector<ReadEvent> reads = poll_schedule(c.poller, c.duration_s, c.seed);
  std::mt19937_64 adc_rng = stream_rng(c.seed, Stream::adc);

  const double period = fp.dt_s, half = 0.5 * period;
  res.control_period_s = period;
  const auto cycles = static_cast<long>(std::ceil(c.duration_s / period));
  bool bridge_on = false;
  std::array<double, 3> duty{0.5, 0.5, 0.5};
  double v_dc = c.power.v_oc_V;
  long ms = 0;
  std::size_t next_read = 0;
  Window window;
  double window_start = 0.0;
  struct SetupAt {
    double t_s;
    SetupValues values;
  };
  std::vector<SetupAt> setups;
  auto legs = [&] { return std::array<double, 3>{duty[0] * v_dc, duty[1] * v_dc, duty[2] * v_dc}; };

  for (long k = 0; k < cycles; ++k) {
    const double t = static_cast<double>(k) * period;
    // The millisecond threads: app, foc timer, mc_interface (temperatures).
    while (static_cast<double>(ms) * 1e-3 <= t + 1e-12) {
      app.step_1ms(static_cast<double>(ms) * 1e-3, fw);
      plant.set_external_torque(c.mechanics.external_Nm + app.external_torque_Nm());
      plant.set_coulomb(c.mechanics.coulomb_Nm + app.added_friction_Nm());
      plant.set_viscous(c.mechanics.viscous_Nm_s + app.added_viscous_Nm_s());
      fw.timer_1ms();
      const double fet = c.sensors.fet_temp_start_C + 0.3 * (t_w - th.winding_start_C);
      // An open NTC input: infinite resistance, which the NTC formula 1/(ln(R/R0)/β + 1/T0) turns into 0 K.
      const double motor_C =
          c.sensors.motor_sensor_fitted != 0.0 ? t_w + c.sensors.motor_temp_noise_K * normal(adc_rng) : -273.15;
      fw.temperatures_1ms(motor_C, fet);
      ++ms;
    }
    if (bridge_on && !fw.running()) {  // stop_pwm_hw forces the outputs off at once
      plant.open_phases(x);
      bridge_on = false;
    }

    // What the ADC sees at the sample (the centre of V0).
    IsrInput in;
    const Vec2 i_ab = bridge_on ? plant.current_ab(x) : Vec2{0.0, 0.0};
    const std::array<double, 3> i_abc = inverse_clarke(i_ab);
    for (int p = 0; p < 3; ++p) {
      in.i_meas_A[p] =
          adc(i_abc[p], c.sensors.current_lsb_A, adc_offset[p], c.sensors.current_noise_lsb, 2048.0, adc_rng, normal);
    }
    if (c.firmware.hall) in.hall_state = hall_state(x.theta_el_rad, hall_offset_rad);  // read in the interrupt
    in.v_bus_meas_V =
        adc(c.sensors.bus_gain * v_dc, c.sensors.voltage_lsb_V, 0.0, c.sensors.voltage_noise_lsb, 0.0, adc_rng, normal);
    const double omega_el = mp.pole_pairs * x.omega_m_rad_s;
    if (!bridge_on) {
      // Undriven phases float at the back EMF around the link's middle; each is measured against ground.
      const double e = c.sensors.phase_voltage_gain * omega_el * plant.params().psi_m_Wb;
      const std::array<double, 3> e_abc = inverse_clarke({-e * std::sin(x.theta_el_rad), e * std::cos(x.theta_el_rad)});
      std::array<double, 3> v_meas{};
      for (int p = 0; p < 3; ++p) {
        v_meas[p] =
            adc(e_abc[p] + 0.5 * v_dc, c.sensors.voltage_lsb_V, 0.0, c.sensors.voltage_noise_lsb, 0.0, adc_rng, normal);
      }
      in.v_terminal_ab_V = clarke(v_meas);
    }
    const IsrOutput out = fw.isr(in);
    const Vec2 i_dq_true = bridge_on ? plant.current_dq(x) : Vec2{0.0, 0.0};
    const double theta_sample = x.theta_el_rad;
    const double eps = wrap_pi(out.phase_rad - theta_sample);
    window.add(out, eps, omega_el, i_dq_true, plant.params().psi_m_Wb, plant.params().r_s_Ohm, t_w, t_m);

    // VESC Tool's requests that arrive before the next interrupt read this one's sums.
    while (next_read < reads.size() && reads[next_read].t_read_s < t + period) {
      const ReadEvent& ev = reads[next_read++];
      const ValuesReply values = fw.read_values();
      const SetupReply setup = fw.read_setup(c.setup, mp.pole_pairs);
      RowTruth truth = window.finish(c.rules);
      truth.t_window_start_s = window_start;
      truth.t_read_s = ev.t_read_s;
      truth.segment = app.kind_now();
      window = Window{};
      window_start = ev.t_read_s;
      ++res.reads;
      if (!ev.logged) {
        ++res.lost_replies;
        continue;
      }
      LogRow row;
      row.t_reply_s = ev.t_reply_s;
      row.context.ms_today = ms_today(c.format.start_ms_today, ev.t_reply_s);
      row.context.values = decode_values(values);
      row.truth = std::move(truth);
      res.rows.push_back(std::move(row));
      setups.push_back({ev.t_setup_reply_s, decode_setup(setup)});
    }

    // The plant over the cycle: the previous duties until the update event half a period on, then the new.
    const IntervalResult first = bridge_on ? plant.step_on(x, half, legs(), v_dc) : plant.step_off(x, half);
    if (out.modulating) {
      duty = out.duty;
      bridge_on = true;
    } else if (bridge_on) {
      plant.open_phases(x);
      bridge_on = false;
    }
    const IntervalResult second = bridge_on ? plant.step_on(x, half, legs(), v_dc) : plant.step_off(x, half);
    window.u_sum = window.u_sum + half * (first.v_dq_mean_V + second.v_dq_mean_V);
    window.i_time_sum = window.i_time_sum + half * (first.i_dq_mean_A + second.i_dq_mean_A);
    window.u_time += period;

    // Temperatures and the battery.
    if (th.on) {
      const double p_cu = (first.energy_cu_J + second.energy_cu_J) / period;
      t_w += period * (p_cu - (t_w - th.ambient_C) / r_th) / c_th;
      t_m += period * (th.ambient_C + th.magnet_coupling * (t_w - th.ambient_C) - t_m) / th.magnet_tau_s;
      plant.set_r_s(r_at(t_w));
      plant.set_psi_m(psi_at(t_m));
      if (!bridge_on) plant.open_phases(x);
    }
    double i_bus = 0.0;
    if (bridge_on) {
      const std::array<double, 3> i_now = inverse_clarke(plant.current_ab(x));
      for (int p = 0; p < 3; ++p) i_bus += duty[p] * i_now[p];
    }
    v_dc = c.power.v_oc_V - c.power.r_internal_Ohm * i_bus;

    if (c.keep_cycle_trace && k % c.trace_every == 0) {
      CycleRecord r;
      r.t_s = t;
      r.theta_el_rad = theta_sample;
      r.omega_el_rad_s = omega_el;
      r.phase_rad = out.phase_rad;
      r.observer_phase_rad = out.observer_phase_rad;
      r.hall_state = in.hall_state;
      r.hall_weight = out.hall_weight;
      r.hall_interpolating = out.hall_interpolating;
      r.source = out.source;
      r.modulating = out.modulating;
      r.i_dq_true_A = i_dq_true;
      r.i_dq_reported_A = fw.i_dq_A();
      r.v_dq_reported_V = fw.v_dq_V();
      r.v_dq_applied_V = 0.5 * (first.v_dq_mean_V + second.v_dq_mean_V);
      r.psi_m_Wb = plant.params().psi_m_Wb;
      r.r_s_Ohm = plant.params().r_s_Ohm;
      r.energy_in_J = first.energy_in_J + second.energy_in_J;
      r.energy_cu_J = first.energy_cu_J + second.energy_cu_J;
      r.energy_load_J = first.energy_load_J + second.energy_load_J;
      r.magnetic_energy_J = bridge_on ? plant.magnetic_energy_J(x) : 0.0;
      r.kinetic_energy_J = plant.kinetic_energy_J(x);
      res.cycles.push_back(r);
    }
  }
  app.finish(c.duration_s);
  res.spans = app.spans();
  res.vesc_measured_flux_Wb = app.measured_flux_linkage_Wb();
  res.end_psi_m_Wb = plant.params().psi_m_Wb;
  res.end_r_s_Ohm = plant.params().r_s_Ohm;
  res.end_T_winding_C = t_w;
  res.end_T_magnet_C = t_m;

  // VESC Tool writes the rows as the replies come; each carries the last setup reply received before it.
  std::stable_sort(res.rows.begin(), res.rows.end(),
                   [](const LogRow& a, const LogRow& b) { return a.t_reply_s < b.t_reply_s; });
  std::sort(setups.begin(), setups.end(), [](const SetupAt& a, const SetupAt& b) { return a.t_s < b.t_s; });
  for (LogRow& row : res.rows) {
    const auto it =
        std::lower_bound(setups.begin(), setups.end(), row.t_reply_s, [](const SetupAt& s, double t) { return s.t_s < t; });
    if (it != setups.begin()) {
      row.context.ms_setup = ms_today(c.format.start_ms_today, std::prev(it)->t_s);
      row.context.setup = std::prev(it)->values;
    }
  }
  return res;
}

}  // namespace indep::vesc
