#include "rpem/core/thermal_fusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rpem/core/clock.hpp"

namespace rpem::core {
namespace {

/// Value and slope of a law, written as θ(T) = slope·T + at_0C.
struct Line {
  double slope;
  double at_0C;
};
Line line_of(const DriftLaw& law) noexcept {
  const double slope = law.value_ref * law.coeff_per_K;
  return {slope, law.value_ref - slope * law.reference_C};
}

}  // namespace

LossBase loss_base_of(const PerUnitBase& base, const MachineSi& machine) noexcept {
  return {base.omega_el_rad_s, machine.psi_m_Wb, base.current_A};
}

ThermalNodeReport report_node(const ThermalEstimate& e, int node, std::int64_t t_ns) noexcept {
  ThermalNodeReport r;
  if (!e.started || node < 0 || node >= e.nodes) {
    r.t_C = r.sd_K = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  const ThermalNodeEstimate& n = e.node[static_cast<std::size_t>(node)];
  r.t_C = n.t_C;
  r.sd_K = n.sigma_K;
  r.source = n.observed ? ThermalSource::observed : ThermalSource::predicted;
  if (n.age_s >= 0.0) r.observed_age_s = n.age_s + std::max(0.0, to_seconds(t_ns - e.t_ns));
  return r;
}

WindingReadout winding_readout(const ThermalFusionConfig& c, const ThermalRates& rates) noexcept {
  const ThermalNetwork& n = c.filter.network;
  WindingReadout r;
  r.row[n.winding] = 1.0;
  if (c.winding_node_is_reading && c.winding_sensor_time_constant_s > 0.0) {
    // A first-order sensor: dT_s/dt = (T_w − T_s)/τ_s, so T_w = T_s + τ_s·dT_s/dt exactly (eq. 14.24).
    const WindingRate rate = winding_rate(n, rates);
    r.row += c.winding_sensor_time_constant_s * rate.row;
    r.constant_K = c.winding_sensor_time_constant_s * rate.constant_K_per_s;
  }
  return r;
}

StepObservations step_observations(const ThermalFusionConfig& c, const ThermalStepData& s, const ThermalRates& rates,
                                   const ThermalVec& t_C, const ThermalVec& dt_dt_K_per_s, const SensorLag& lag) noexcept {
  const ThermalNetwork& n = c.filter.network;
  const Line magnet = line_of(c.magnet_law), copper = line_of(n.copper);
  const int m = n.magnet, w = n.winding;
  StepObservations out;
  // [node of the parameter's own temperature, the other node], the laws, the law's calibration states.
  struct Row {
    int own, other;
    Line own_law, other_law;
    double reference_C;
    Calibration offset, coefficient;
  };
  const Row rows[2] = {
      {m, w, magnet, copper, c.magnet_law.reference_C, Calibration::kMagnetOffset, Calibration::kMagnetCoefficient},
      {w, m, copper, magnet, n.copper.reference_C, Calibration::kCopperOffset, Calibration::kCopperCoefficient}};
  const WindingReadout g = winding_readout(c, rates);  // the winding the parameters see (eq. 14.24)
  for (std::size_t j = 0; j < 2; ++j) {
    const ParameterObservation& p = s.parameter[j];
    if (!p.valid) continue;
    const Row& r = rows[j];
    ThermalObservation& o = out.item[j];
    o.h[r.own] = r.own_law.slope;
    o.h[r.other] = p.cross * r.other_law.slope;
    o.offset = r.own_law.at_0C + p.cross * (r.other_law.at_0C - p.other_held);
    o.value = p.value;
    // T' = T + e_ref + e_α·(T − T_ref), linearised at T̂ (eq. 14.10).
    o.h_c[static_cast<int>(r.offset)] = r.own_law.slope;
    o.h_c[static_cast<int>(r.coefficient)] = r.own_law.slope * (t_C[r.own] - r.reference_C);
    // ... and the product e_α·(T − T̂) the linearisation leaves out, which the filter takes over its prior (14.10a).
    o.bilinear = r.own_law.slope;
    o.bilinear_node = r.own;
    o.bilinear_state = r.coefficient;
    const double lag_K = dt_dt_K_per_s[r.own] * p.time_constant_s;
    o.variance = p.variance + r.own_law.slope * r.own_law.slope * lag_K * lag_K;
    if (c.winding_node_is_reading) {
      // r̂s and ψ̂m's κ term see the winding, which leads the node that stands for the reading (eq. 14.24), its
      // rate holding the coolant's error (eq. 14.29a).
      const double h_w = o.h[w];
      o.h[w] = 0.0;
      o.h += h_w * g.row.head<kMaxThermalNodes>();
      o.h_d += h_w * g.row.segment<kMaxThermalNodes>(kMaxThermalNodes);
      o.h_c += h_w * g.row.tail<kCalibrationStates>();
      o.offset += h_w * g.constant_K;
    }
    out.present[j] = true;
  }
  if (c.winding_sensor_sigma_K > 0.0 && std::isfinite(s.winding_sensor_C)) {
    ThermalObservation& o = out.item[2];
    o.h[w] = 1.0;
    o.value = s.winding_sensor_C;
    o.variance = c.winding_sensor_sigma_K * c.winding_sensor_sigma_K;
    // With the node standing for the reading, the sensor observes it as it is (eq. 14.24).
    const double lag_s = c.winding_node_is_reading ? 0.0 : c.winding_sensor_time_constant_s;
    const SensorLagStep k = sensor_lag_step(lag_s, s.load.dt_s, s.winding_sensor_age);
    if (k.rate_s > 0.0) {
      // The step's mean reading T_w − κ·(A_w·T + u_w + d_w/C_w + (G_w0/C_w)·e_c) − β·e (eq. 14.22, 14.29a); e's
      // error in the variance.
      const WindingRate rate = winding_rate(n, rates);
      o.h -= k.rate_s * rate.row.head<kMaxThermalNodes>();
      o.h_d = -k.rate_s * rate.row.segment<kMaxThermalNodes>(kMaxThermalNodes);
      o.h_c = -k.rate_s * rate.row.tail<kCalibrationStates>();
      o.offset = -k.rate_s * rate.constant_K_per_s - k.carry * lag.lag_K;
      o.variance += k.carry * k.carry * lag.variance_K2;
    }
    out.present[2] = true;
  }
  return out;
}

ThermalFusion::ThermalFusion(const ThermalFusionConfig& config, const PerUnitBase& base, const MachineSi& machine) noexcept
    : config_(config),
      observer_(config.observer, base, machine, config.filter.network.base, config.coolant_C),
      filter_(config.filter) {
  out_.nodes = config.filter.network.nodes;
  out_.winding = config.filter.network.winding;
  out_.magnet = config.filter.network.magnet;
}

void ThermalFusion::reconfigure(const ThermalFusionConfig& config, const PerUnitBase& base,
                                const MachineSi& machine) noexcept {
  config_ = config;
  observer_.reconfigure(config.observer, base, machine, config.filter.network.base, config.coolant_C);
  filter_.reconfigure(config.filter);
  out_.nodes = config.filter.network.nodes;
  out_.winding = config.filter.network.winding;
  out_.magnet = config.filter.network.magnet;
}

ThermalVec start_temperatures_C(const ThermalFusionConfig& c, const ThermalStepData& s) noexcept {
  ThermalVec t = ThermalVec::Constant(s.load.coolant_C);
  if (c.winding_sensor_sigma_K > 0.0 && std::isfinite(s.winding_sensor_C)) {
    if (unsoaked_excess_K(s.winding_sensor_C, s.load.coolant_C, c.winding_sensor_sigma_K) != 0.0) {
      for (int i = 0; i < c.filter.network.nodes; ++i) t[i] = s.winding_sensor_C;
    }
    t[c.filter.network.winding] = s.winding_sensor_C;
  }
  return t;
}

ThermalSnapshot ThermalFusion::snapshot() const noexcept {
  ThermalSnapshot s;
  if (!out_.started) return s;
  const ThermalNetwork& n = config_.filter.network;
  s.nodes = n.nodes;
  s.winding = n.winding;
  s.magnet = n.magnet;
  s.t_C = filter_.temperature_C();
  s.p_K2 = filter_.covariance().topLeftCorner<kMaxThermalNodes, kMaxThermalNodes>();
  s.load = last_load_;
  return s;
}

bool ThermalFusion::resume(const ThermalSnapshot& saved, double gap_s) noexcept {
  if (!fits_network(saved, config_.filter.network)) return false;
  resumed_ = across_unknown_load(config_.filter, saved, gap_s, config_.observer.period_s);
  return true;
}

void ThermalFusion::start(const ThermalStepData& s) noexcept {
  sensor_lag_ = SensorLag{};  // the sensor at the winding's temperature
  // A restart: where the saved state stands now.
  if (fits_network(resumed_, config_.filter.network)) {
    filter_.set_temperatures(resumed_.t_C, resumed_.p_K2);
    out_.started = true;
    out_.start_assumed_soaked = false;
    return;
  }
  ThermalMat p = ThermalMat::Identity() * (config_.initial_sigma_K * config_.initial_sigma_K);
  // Not soaked (a restart on a warm machine): each node within the winding's distance from the coolant — a magnet
  // anywhere from the coolant to as far above the winding.
  const double excess_K = config_.winding_sensor_sigma_K > 0.0 && std::isfinite(s.winding_sensor_C)
                              ? unsoaked_excess_K(s.winding_sensor_C, s.load.coolant_C, config_.winding_sensor_sigma_K)
                              : 0.0;
  for (int i = 0; i < config_.filter.network.nodes; ++i) p(i, i) = std::max(p(i, i), excess_K * excess_K);
  filter_.set_temperatures(start_temperatures_C(config_, s), p);
  held_reading_.restart();
  ThermalStepData without = s;
  without.winding_sensor_C = std::numeric_limits<double>::quiet_NaN();
  start_without_reading_C_ = start_temperatures_C(config_, without);
  first_step_ = true;
  out_.started = true;
  out_.start_assumed_soaked = !(config_.winding_sensor_sigma_K > 0.0 && std::isfinite(s.winding_sensor_C));
}

void ThermalFusion::step(const Estimate& e, const ThermalSample& s) noexcept {
  if (observer_.add(e, s)) apply(observer_.step());
}

void ThermalFusion::apply(const ThermalStepData& d) noexcept {
  if (!out_.started) start(d);
  const ThermalRates rates = thermal_rates(config_.filter.network, d.load);
  filter_.predict(d.load, rates);
  if (d.coolant_read) filter_.coolant_read();  // the coolant's error starts again (eq. 14.29)
  last_load_ = d.load;
  finish_step(d, rates, d.load.dt_s);
}

void ThermalFusion::coast(double dt_s) noexcept {
  if (!out_.started || !(dt_s > 0.0)) return;
  ThermalLoad l = last_load_;
  l.dt_s = dt_s;
  const ThermalRates rates = thermal_rates(config_.filter.network, l);
  filter_.predict(l, rates);
  ThermalStepData none;
  none.t_ns = out_.t_ns + static_cast<std::int64_t>(dt_s * 1e9);
  none.load = l;
  none.psi_m_Wb = last_psi_m_Wb_;
  none.r_s_Ohm = last_r_s_Ohm_;
  finish_step(none, rates, dt_s);
}

StepObservations ThermalFusion::observations_now(const ThermalStepData& d, const ThermalRates& rates) const noexcept {
  const ThermalVec slope = rates.a * filter_.temperature_C() + rates.u;
  return step_observations(config_, d, rates, filter_.temperature_C(), slope, sensor_lag_);
}

ReadingMotion ThermalFusion::check_held_reading(const ThermalStepData& d, const ThermalRates& rates,
                                                StepObservations& obs) noexcept {
  held_reading_.advance(filter_);
  const bool present = obs.present[kSensorObservation];
  const ReadingMotion motion =  // a step without a reading holds nothing
      present ? held_reading_.check(filter_, obs.item[kSensorObservation]) : ReadingMotion::kMoved;
  if (present && motion == ReadingMotion::kMoved) {
    sensor_taken_since_move_ = false;
    if (first_step_) {  // the value set the start: without it the filter starts where start_without_reading_ says
      ThermalVec d_W = ThermalVec::Zero();
      filter_.advance_open_loop(start_without_reading_C_, d_W);
      held_reading_.retarget(start_without_reading_C_, d_W);
    }
  }
  first_step_ = false;
  if (motion == ReadingMotion::kFrozenNow && sensor_taken_since_move_) {  // nothing to withdraw where none was taken
    filter_.withdraw_to(held_reading_.target_temperature_C(), held_reading_.target_disturbance_W());
    obs = observations_now(d, rates);
  }
  return motion;
}

ObservationResult ThermalFusion::apply_observation(std::size_t k, const ThermalObservation& o, int node,
                                                   ReadingMotion motion) noexcept {
  const bool sensor = k == kSensorObservation;
  if (sensor && is_frozen(motion)) {
    reports_[k] = {true, ObservationResult::kRejectedHeld, 0.0, filter_.innovation_variance(o)};
    out_.winding_reading_held = true;
    ++out_.winding_readings_held;
    return ObservationResult::kRejectedHeld;
  }
  ObservationResult result = filter_.observe(o);
  reports_[k] = {true, result, filter_.last_innovation(), filter_.last_innovation_variance()};
  if (sensor && result == ObservationResult::kRejectedGate) {
    // A run of refusals says the model drifted only where the refused readings move (thermal_held_reading.hpp).
    sensor_moved_in_run_ = rejected_in_a_row_[k] > 0 && (sensor_moved_in_run_ || motion == ReadingMotion::kMoved);
  }
  const int reset_after = config_.filter.gate_reset_after;
  if (result == ObservationResult::kRejectedGate && reset_after > 0 && ++rejected_in_a_row_[k] >= reset_after) {
    if (sensor && !sensor_moved_in_run_) {
      out_.winding_reading_held = true;
      ++out_.winding_readings_held;
    } else {
      // The observations keep disagreeing: the model has drifted. Open the node's variance to the miss.
      filter_.inflate(node, filter_.last_innovation() * filter_.last_innovation() / (o.h[node] * o.h[node]));
      result = filter_.observe(o);
      ++out_.gate_resets;
    }
  }
  if (result != ObservationResult::kRejectedGate) rejected_in_a_row_[k] = 0;
  if (result == ObservationResult::kAccepted) sensor_taken_since_move_ = sensor_taken_since_move_ || sensor;
  return result;
}

void ThermalFusion::finish_step(const ThermalStepData& d, const ThermalRates& rates, double dt_s) noexcept {
  const ThermalNetwork& n = config_.filter.network;
  StepObservations obs = observations_now(d, rates);
  // A winding reading that does not move while the network says it must is refused, and what it had told the
  // filter withdrawn (eq. 14.28); the other observations are then formed at the withdrawn state.
  const ReadingMotion motion = check_held_reading(d, rates, obs);
  out_.winding_reading_held = false;
  const int node_of[3] = {n.magnet, n.winding, n.winding};
  std::array<bool, kMaxThermalNodes> observed{};
  for (std::size_t k = 0; k < obs.item.size(); ++k) {
    reports_[k] = ObservationReport{};
    if (!obs.present[k]) continue;
    if (apply_observation(k, obs.item[k], node_of[k], motion) == ObservationResult::kAccepted) {
      ++out_.observations_accepted;
      observed[static_cast<std::size_t>(node_of[k])] = true;
    } else {
      ++out_.observations_rejected;
    }
  }
  if (config_.winding_sensor_time_constant_s > 0.0 && !config_.winding_node_is_reading) {
    // The sensor's lag over this step at the posterior's rate of the winding (eq. 14.22), that rate's variance
    // from the posterior covariance of the whole state along its row (e_c's mean is zero, its variance is not:
    // eq. 14.29a).
    const WindingRate g = winding_rate(n, rates);
    const double rate = g.row.head<kMaxThermalNodes>().dot(filter_.temperature_C()) +
                        g.row.segment<kMaxThermalNodes>(kMaxThermalNodes).dot(filter_.disturbance_W()) + g.constant_K_per_s;
    const double rate_variance = g.row.dot(filter_.covariance() * g.row);
    sensor_lag_.advance(sensor_lag_step(config_.winding_sensor_time_constant_s, dt_s, d.winding_sensor_age), rate,
                        rate_variance);
  }
  last_psi_m_Wb_ = d.psi_m_Wb;
  last_r_s_Ohm_ = d.r_s_Ohm;
  out_.t_ns = d.t_ns;
  out_.coolant_C = d.load.coolant_C;
  // The winding as reported: the node, or the node led by the sensor's τ_s (eq. 14.24), its variance g·P·gᵀ over
  // the whole state (the coolant's error moves the rate, eq. 14.29a; its mean is zero).
  const WindingReadout g = winding_readout(config_, rates);
  Eigen::Matrix<double, kDynamicThermalStates, 1> x_dyn;
  x_dyn << filter_.temperature_C(), filter_.disturbance_W();
  for (int i = 0; i < kMaxThermalNodes; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ThermalNodeEstimate& node = out_.node[k];
    node.t_C = filter_.temperature_C()[i];
    node.sigma_K = filter_.sigma_K(i);
    if (i == n.winding && config_.winding_node_is_reading) {
      node.t_C = g.row.head<kDynamicThermalStates>().dot(x_dyn) + g.constant_K;
      node.sigma_K = std::sqrt(std::max(g.row.dot(filter_.covariance() * g.row), 0.0));
    }
    node.observed = observed[k];
    if (observed[k]) {
      ever_observed_[k] = true;
      since_observed_s_[k] = 0.0;
    } else {
      since_observed_s_[k] += dt_s;
    }
    node.age_s = ever_observed_[k] ? since_observed_s_[k] : -1.0;
  }
  out_.t_magnet_rpem_C = config_.magnet_law.temperature_C(d.psi_m_Wb);
  out_.t_winding_rpem_C = n.copper.temperature_C(d.r_s_Ohm);
}

}  // namespace rpem::core
