#include "rpem/analysis/diagnose/replay.hpp"

#include <cmath>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/predictor.hpp"

namespace rpem::analysis {
namespace {

/// A gap longer than this many median intervals restarts the predictor from the measurement.
constexpr double kMaxIntervals = 8.0;

}  // namespace

ModelReplay::ModelReplay(const LogData& log, const core::MachineSi& machine, double reference_C)
    : log_(log),
      base_(core::PerUnitBase::from_rated(machine.rated)),
      nominal_(core::to_pu(base_, machine)),
      reference_C_(reference_C),
      max_interval_s_(kMaxIntervals * log.median_dt_s) {}

void ModelReplay::drifted(const ExtendedModel& model, std::size_t k, core::MachinePu& m) const noexcept {
  const io::DriveLogRow& row = log_.rows[k];
  const double tau = log_.time_fraction(k);
  m.r_s_pu = nominal_.r_s_pu * drift_factor(model.r_s, tau, row.t_winding_C, reference_C_);
  m.psi_m_pu = nominal_.psi_m_pu * drift_factor(model.psi_m, tau, row.t_magnet_C, reference_C_);
}

void ModelReplay::run(const ExtendedModel& model, ReplayOutput& out) const {
  const std::size_t n = log_.rows.size();
  out.residual_A.assign(n, core::Vec2::Zero());
  out.model_A.assign(n, core::Vec2::Zero());
  out.valid.assign(n, false);
  if (log_.mode == ModelMode::kTransient) {
    run_transient(model, out);
  } else {
    run_steady_state(model, out);
  }
}

void ModelReplay::run_transient(const ExtendedModel& model, ReplayOutput& out) const {
  core::SampleConditioner conditioner(base_, nominal_, model.extensions);
  core::PredictorState state;
  core::MachinePu m = nominal_;
  const core::PredictorCoefficients nominal_coefficients = core::PredictorCoefficients::of(nominal_, base_.omega_el_rad_s);
  bool synchronized = false;
  for (std::size_t k = 0; k < log_.rows.size(); ++k) {
    core::DriveSample s = log_.rows[k].sample;
    s.omega_el_rad_s = log_.replay_speed_rad_s[k];
    const core::EstimatorSample e = conditioner.condition(s);
    if (!e.i_meas_pu.allFinite()) {
      synchronized = false;
      continue;
    }
    const auto& iv = e.interval;
    if (e.resync || !synchronized || !(iv.dt_s > 0.0) || iv.dt_s > max_interval_s_) {
      state.i_hat_pu = e.i_meas_pu;  // the open-loop prediction starts from the measurement
      synchronized = true;
      continue;
    }
    drifted(model, k, m);
    core::PredictorCoefficients coefficients = nominal_coefficients;
    if (e.x_d_pu > 0.0) {
      m.x_d_pu = e.x_d_pu;
      m.x_q_pu = e.x_q_pu;
      coefficients = core::PredictorCoefficients::of(m, base_.omega_el_rad_s);
    }
    core::predict(m, coefficients, core::Discretization::kTrapezoidal, iv, state, core::Gradients::kSkip);
    if (!log_.used[k]) continue;
    out.model_A[k] = conditioner.observed_current_dq_A(s, state.i_hat_pu);
    out.residual_A[k] = conditioner.logged_current_dq_A(s) - out.model_A[k];
    out.valid[k] = out.residual_A[k].allFinite();
  }
}

void ModelReplay::run_steady_state(const ExtendedModel& model, ReplayOutput& out) const {
  const core::SampleConditioner conditioner(base_, nominal_, model.extensions);
  core::MachinePu m = nominal_;
  for (std::size_t k = 0; k < log_.rows.size(); ++k) {
    if (!log_.used[k]) continue;
    const core::DriveSample& s = log_.rows[k].sample;
    const core::SteadyStateInputs in = conditioner.steady_state(s);
    drifted(model, k, m);
    m.x_d_pu = in.x_d_pu;
    m.x_q_pu = in.x_q_pu;
    const core::Vec2 i_model_pu = core::steady_state_current(m, in.n_pu, in.u_pu);
    out.model_A[k] = conditioner.observed_current_dq_A(s, i_model_pu);
    out.residual_A[k] = conditioner.logged_current_dq_A(s) - out.model_A[k];
    out.valid[k] = out.residual_A[k].allFinite();
  }
}

}  // namespace rpem::analysis
