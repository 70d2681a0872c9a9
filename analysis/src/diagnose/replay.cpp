#include "rpem/analysis/diagnose/replay.hpp"

#include <algorithm>
#include <cmath>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/predictor.hpp"

namespace rpem::analysis {
namespace {

/// A gap longer than this many median intervals restarts the predictor from the measurement.
constexpr double kMaxIntervals = 8.0;
/// Samples before a block that pass through the conditioner only (its command history for delays).
constexpr std::size_t kWarmup = core::kMaxDelayPeriods + 3;

}  // namespace

ModelReplay::ModelReplay(const LogData& log, const core::RatedData& rated)
    : log_(log), base_(core::PerUnitBase::from_rated(rated)), max_interval_s_(kMaxIntervals * log.median_dt_s) {
  const std::size_t n = log.rows.size();
  if (log.mode == ModelMode::kTransient) {
    logged_rotation_.resize(log.replay_samples.size());
    for (std::size_t k = 0; k < logged_rotation_.size(); ++k) logged_rotation_[k] = core::Rotation::of(log.replay_samples[k].theta_el_rad);
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!log.block_start(k)) continue;
    if (!blocks_.empty()) blocks_.back().end = k;
    blocks_.push_back({k >= kWarmup ? k - kWarmup : 0, k, n});
  }
}

bool ModelReplay::selected(std::size_t k, Blocks blocks) const noexcept {
  switch (blocks) {
    case Blocks::kAll: return true;
    case Blocks::kTraining: return log_.block[k] % 2 == 0;
    case Blocks::kHeldout: return log_.block[k] % 2 == 1;
  }
  return true;
}

void ModelReplay::run(const ExtendedModel& model, ReplayOutput& out, Blocks blocks) const {
  const std::size_t n = log_.rows.size();
  out.residual_A.assign(n, core::Vec2::Zero());
  out.model_A.assign(n, core::Vec2::Zero());
  out.valid.assign(n, false);
  if (log_.mode == ModelMode::kTransient) {
    run_transient(model, out, blocks);
  } else {
    run_steady_state(model, out, blocks);
  }
}

void ModelReplay::run_transient(const ExtendedModel& model, ReplayOutput& out, Blocks blocks) const {
  const core::MachinePu machine = core::to_pu(base_, model.machine);
  core::SampleConditioner conditioner(base_, machine, model.extensions);
  const core::PredictorCoefficients constant = core::PredictorCoefficients::of(machine, base_.omega_el_rad_s);
  const double inv_impedance = 1.0 / base_.impedance_Ohm, inv_flux = 1.0 / base_.flux_Wb;
  core::PredictorState state;
  core::MachinePu m = machine;
  const bool drifting = model.r_s_law || model.psi_m_law || model.r_s_trend != 0.0 || model.psi_m_trend != 0.0;
  std::size_t previous_end = 0;
  for (const Stretch& b : blocks_) {
    if (!selected(b.first, blocks)) continue;
    const std::size_t begin = std::max(b.begin, previous_end);
    if (begin != previous_end || previous_end == 0) conditioner.reset();  // not contiguous with the last one
    previous_end = b.end;
    bool synchronized = false;
    for (std::size_t k = begin; k < b.end; ++k) {
      const core::DriveSample& s = log_.replay_samples[k];
      const core::EstimatorSample e = conditioner.condition(s);
      if (k < b.first) continue;  // warm-up
      if (!e.i_meas_pu.allFinite()) {
        synchronized = false;
        continue;
      }
      const auto& iv = e.interval;
      if (k == b.first || e.resync || !synchronized || !(iv.dt_s > 0.0) || iv.dt_s > max_interval_s_) {
        state.i_hat_pu = e.i_meas_pu;  // the open-loop prediction starts from the measurement
        synchronized = true;
        continue;
      }
      if (drifting) {
        m.r_s_pu = r_s_at(model, log_, k) * inv_impedance;
        m.psi_m_pu = psi_m_at(model, log_, k) * inv_flux;
      }
      core::PredictorCoefficients coefficients = constant;
      if (e.x_d_pu > 0.0) {
        m.x_d_pu = e.x_d_pu;
        m.x_q_pu = e.x_q_pu;
        coefficients = core::PredictorCoefficients::of(m, base_.omega_el_rad_s);
      }
      core::predict(m, coefficients, core::Discretization::kTrapezoidal, iv, state, core::Gradients::kSkip);
      if (!log_.used[k]) {
        // Left out (its regime excluded it: bridge off, not locked): the model does not describe it, so the
        // prediction starts again from the measurement after it.
        synchronized = false;
        continue;
      }
      out.model_A[k] = conditioner.observed_current_dq_A(s, logged_rotation_[k], state.i_hat_pu);
      out.residual_A[k] = log_.logged_i_dq_A[k] - out.model_A[k];
      out.valid[k] = out.residual_A[k].allFinite();
    }
  }
}

void ModelReplay::run_steady_state(const ExtendedModel& model, ReplayOutput& out, Blocks blocks) const {
  const core::MachinePu machine = core::to_pu(base_, model.machine);
  const core::SampleConditioner conditioner(base_, machine, model.extensions);
  core::MachinePu m = machine;
  for (std::size_t k = 0; k < log_.rows.size(); ++k) {
    if (!log_.used[k] || !selected(k, blocks)) continue;
    const core::DriveSample& s = log_.rows[k].sample;
    const core::SteadyStateInputs in = conditioner.steady_state(s);
    m.r_s_pu = base_.resistance_pu(r_s_at(model, log_, k));
    m.psi_m_pu = base_.flux_pu(psi_m_at(model, log_, k));
    m.x_d_pu = in.x_d_pu;
    m.x_q_pu = in.x_q_pu;
    const core::Vec2 i_model_pu = core::steady_state_current(m, in.n_pu, in.u_pu);
    out.model_A[k] = conditioner.observed_current_dq_A(s, i_model_pu);
    out.residual_A[k] = log_.logged_i_dq_A[k] - out.model_A[k];
    out.valid[k] = out.residual_A[k].allFinite();
  }
}

}  // namespace rpem::analysis
