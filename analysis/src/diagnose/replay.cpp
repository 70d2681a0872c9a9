#include "rpem/analysis/diagnose/replay.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "rpem/core/conditioner.hpp"
#include "rpem/core/predictor.hpp"

namespace rpem::analysis {
namespace {

/// A gap longer than this many median intervals restarts the predictor from the measurement.
constexpr double kMaxIntervals = 8.0;
/// Samples before a block that pass through the conditioner only (its command history for delays).
constexpr std::size_t kWarmup = core::kMaxDelayPeriods + 3;

/// What every model of a replay shares at one sample.
struct Shared {
  core::DriveSample s;    ///< as the replay takes it (LogData::replay_sample)
  core::Rotation logged;  ///< at the logged angle
};

/// Whether two models are the same bit for bit, field by field (ModelExtensions and the machine hold doubles
/// only): their replays then are too.
bool same_bits(const ExtendedModel& a, const ExtendedModel& b) noexcept {
  // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): bit for bit is the intent (a -0.0 or a NaN payload may replay differently)
  const auto bytes = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  const auto law = [&](const std::optional<core::DriftLaw>& x, const std::optional<core::DriftLaw>& y) {
    return x.has_value() == y.has_value() && (!x || bytes(*x, *y));
  };
  return bytes(a.machine, b.machine) && bytes(a.extensions, b.extensions) && law(a.r_s_law, b.r_s_law) &&
         law(a.psi_m_law, b.psi_m_law) && bytes(a.r_s_trend, b.r_s_trend) && bytes(a.psi_m_trend, b.psi_m_trend);
}

}  // namespace

/// One model's replay through a block: its conditioner and predictor state, sample by sample.
class ModelReplay::Chain {
 public:
  Chain(const ModelReplay& r, const ExtendedModel& model)
      : r_(r),
        model_(model),
        machine_(core::to_pu(r.base_, model.machine)),
        conditioner_(r.base_, machine_, model.extensions),
        constant_(core::PredictorCoefficients::of(machine_, r.base_.omega_el_rad_s)),
        m_(machine_),
        drifting_(model.r_s_law || model.psi_m_law || model.r_s_trend != 0.0 || model.psi_m_trend != 0.0) {}

  /// Whether `other`'s conditioner gives this one's conditioned samples, bit for bit: the same extensions
  /// (compared as bytes: ModelExtensions holds doubles only) and, where they read it, the same machine
  /// (the base is the replay's). A model moved along a calibrated constant or a drift shares its samples
  /// with the model it was moved from.
  [[nodiscard]] bool conditions_like(const Chain& other) const noexcept {
    const core::ModelExtensions &a = model_.extensions, &b = other.model_.extensions;
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): bit for bit is the intent (a -0.0 or a NaN payload may condition differently)
    if (std::memcmp(&a, &b, sizeof a) != 0) return false;
    // NOLINTNEXTLINE(bugprone-suspicious-memory-comparison): as above; a padding byte that differs only costs the sharing
    return !a.reads_machine() || std::memcmp(&machine_, &other.machine_, sizeof machine_) == 0;
  }
  /// The sample as this chain's conditioner turns it into the predictor's interval (a chain that conditions
  /// like another takes that one's instead, replay_block).
  core::EstimatorSample condition(const Shared& x) noexcept { return conditioner_.condition(x.s); }

  /// Transient: sample k of a block whose own samples start at `first` (earlier ones warm the conditioner
  /// up), `e` the sample conditioned (condition()); `out` is filled for the block's own samples that take part.
  void step_transient(std::size_t k, std::size_t first, const Shared& x, const core::EstimatorSample& e,
                      const core::Vec2* logged_i_dq_A, ModelSample& out) {
    if (k < first) return;  // warm-up
    out = ModelSample{};
    if (!e.i_meas_pu.allFinite()) {
      synchronized_ = false;
      return;
    }
    const auto& iv = e.interval;
    if (k == first || e.resync || !synchronized_ || !(iv.dt_s > 0.0) || iv.dt_s > r_.max_interval_s_) {
      state_.i_hat_pu = e.i_meas_pu;  // the open-loop prediction starts from the measurement
      synchronized_ = true;
      return;
    }
    if (drifting_) {
      m_.r_s_pu = r_s_at(model_, r_.log_, k) * (1.0 / r_.base_.impedance_Ohm);
      m_.psi_m_pu = psi_m_at(model_, r_.log_, k) * (1.0 / r_.base_.flux_Wb);
    }
    core::PredictorCoefficients coefficients = constant_;
    if (e.x_d_pu > 0.0) {
      m_.x_d_pu = e.x_d_pu;
      m_.x_q_pu = e.x_q_pu;
      coefficients = core::PredictorCoefficients::of(m_, r_.base_.omega_el_rad_s);
    }
    core::predict(m_, coefficients, core::Discretization::kTrapezoidal, iv, state_, core::Gradients::kSkip);
    if (logged_i_dq_A == nullptr) {
      // Left out (its regime excluded it: bridge off, not locked): the model does not describe it, so the
      // prediction starts again from the measurement after it.
      synchronized_ = false;
      return;
    }
    out.model_A = conditioner_.observed_current_dq_A(x.s, x.logged, state_.i_hat_pu);
    out.residual_A = *logged_i_dq_A - out.model_A;
    out.valid = out.residual_A.allFinite();
    if (!out.valid) out.residual_A.setZero();
  }

  /// Steady state: sample k on its own.
  void step_steady(std::size_t k, const Shared& x, const core::Vec2& logged_i_dq_A, ModelSample& out) {
    const core::SteadyStateInputs in = conditioner_.steady_state(x.s);
    m_.r_s_pu = r_.base_.resistance_pu(r_s_at(model_, r_.log_, k));
    m_.psi_m_pu = r_.base_.flux_pu(psi_m_at(model_, r_.log_, k));
    m_.x_d_pu = in.x_d_pu;
    m_.x_q_pu = in.x_q_pu;
    const core::Vec2 i_model_pu = core::steady_state_current(m_, in.n_pu, in.u_pu);
    out.model_A = conditioner_.observed_current_dq_A(x.s, x.logged, i_model_pu);
    out.residual_A = logged_i_dq_A - out.model_A;
    out.valid = out.residual_A.allFinite();
    if (!out.valid) out.residual_A.setZero();
  }

 private:
  const ModelReplay& r_;
  const ExtendedModel& model_;
  core::MachinePu machine_;
  core::SampleConditioner conditioner_;
  core::PredictorCoefficients constant_;
  core::PredictorState state_;
  core::MachinePu m_;
  bool drifting_;
  bool synchronized_ = false;
};

ModelReplay::ModelReplay(const LogData& log, const core::RatedData& rated, const WorkPool& pool, Monitor* monitor)
    : log_(log),
      base_(core::PerUnitBase::from_rated(rated)),
      max_interval_s_(kMaxIntervals * log.median_dt_s),
      pool_(pool),
      monitor_(monitor) {}

std::vector<int> ModelReplay::blocks(Blocks which) const {
  std::vector<int> out;
  for (int b = 0; b < log_.blocks; ++b) {
    if (log_.block_first[static_cast<std::size_t>(b)] == log_.block_first[static_cast<std::size_t>(b) + 1]) continue;
    if ((which == Blocks::kTraining && b % 2 != 0) || (which == Blocks::kHeldout && b % 2 != 1)) continue;
    out.push_back(b);
  }
  return out;
}

void ModelReplay::for_blocks(const std::vector<int>& blocks, const std::function<void(std::size_t, int)>& per_block) const {
  pool_.parallel_for(blocks.size(), [&](std::size_t i) {
    if (monitor_ && monitor_->stop_requested()) throw Interrupted();
    per_block(i, blocks[i]);
  });
}

std::vector<std::size_t> ModelReplay::distinct_chains(std::span<const ExtendedModel> models,
                                                      std::vector<Chain>& chains) const {
  std::vector<std::size_t> chain_of(models.size());
  chains.reserve(models.size());
  for (std::size_t j = 0; j < models.size(); ++j) {
    chain_of[j] = chains.size();
    for (std::size_t i = 0; i < j; ++i) {
      if (same_bits(models[i], models[j])) {
        chain_of[j] = chain_of[i];
        break;
      }
    }
    if (chain_of[j] == chains.size()) chains.emplace_back(*this, models[j]);
  }
  return chain_of;
}

std::vector<std::size_t> ModelReplay::shared_conditioners(const std::vector<Chain>& chains) {
  std::vector<std::size_t> conditioned_by(chains.size());
  for (std::size_t j = 0; j < chains.size(); ++j) {
    conditioned_by[j] = j;
    for (std::size_t i = 0; i < j; ++i) {
      if (conditioned_by[i] == i && chains[i].conditions_like(chains[j])) {
        conditioned_by[j] = i;
        break;
      }
    }
  }
  return conditioned_by;
}

void ModelReplay::replay_block(int b, std::span<const ExtendedModel> models, const Visit& visit) const {
  const std::size_t first = log_.block_first[static_cast<std::size_t>(b)],
                    end = log_.block_first[static_cast<std::size_t>(b) + 1];
  // A model the same as an earlier one bit for bit (a screening's candidate at a start that leaves the model as
  // it is: the round's model) steps no chain of its own: it is given that one's samples.
  std::vector<Chain> chains;
  const std::vector<std::size_t> chain_of = distinct_chains(models, chains);
  const bool repeated = chains.size() < models.size();
  std::vector<ModelSample> out(chains.size()), all(repeated ? models.size() : 0);
  const auto visit_all = [&](std::size_t k) {
    if (!repeated) return visit(k, out);
    for (std::size_t j = 0; j < all.size(); ++j) all[j] = out[chain_of[j]];
    visit(k, all);
  };
  Shared x;
  if (log_.mode == ModelMode::kTransient) {
    // The models that condition alike share one conditioner's samples: the first of each kind conditions.
    const std::vector<std::size_t> conditioned_by = shared_conditioners(chains);
    std::vector<core::EstimatorSample> conditioned(chains.size());
    for (std::size_t k = first >= kWarmup ? first - kWarmup : 0; k < end; ++k) {
      x.s = log_.replay_sample(k);
      x.logged = core::Rotation::of(x.s.theta_el_rad);
      const bool own = k >= first, used = own && log_.used(k);
      const core::Vec2 logged = used ? core::SampleConditioner::logged_current_dq_A(x.s, x.logged) : core::Vec2::Zero();
      for (std::size_t j = 0; j < chains.size(); ++j) {
        if (conditioned_by[j] == j) conditioned[j] = chains[j].condition(x);
      }
      for (std::size_t j = 0; j < chains.size(); ++j) {
        chains[j].step_transient(k, first, x, conditioned[conditioned_by[j]], used ? &logged : nullptr, out[j]);
      }
      if (used) visit_all(k);
    }
  } else {
    for (std::size_t k = first; k < end; ++k) {
      if (!log_.used(k)) continue;
      x.s = log_.sample(k);
      x.logged = core::Rotation::of(x.s.theta_el_rad);
      const core::Vec2 logged = core::SampleConditioner::logged_current_dq_A(x.s, x.logged);
      for (std::size_t j = 0; j < chains.size(); ++j) chains[j].step_steady(k, x, logged, out[j]);
      visit_all(k);
    }
  }
  if (monitor_) monitor_->advance(static_cast<std::uint64_t>(end - first) * models.size());
}

void ModelReplay::run(const ExtendedModel& model, ReplayOutput& out, Blocks which) const {
  const std::size_t n = log_.size();
  out.residual_A.assign(n, core::Vec2::Zero());
  out.model_A.assign(n, core::Vec2::Zero());
  out.valid.assign(n, false);
  // Each block writes its own samples only: the vectors' elements (not vector<bool>'s bits) are safe to
  // share; the bits are set afterwards.
  std::vector<char> valid(n, 0);
  for_blocks(blocks(which), [&](std::size_t, int b) {
    replay_block(b, std::span(&model, 1), [&](std::size_t k, std::span<const ModelSample> m) {
      out.residual_A[k] = m[0].residual_A;
      out.model_A[k] = m[0].model_A;
      valid[k] = m[0].valid ? 1 : 0;
    });
  });
  for (std::size_t k = 0; k < n; ++k) out.valid[k] = valid[k] != 0;
}

}  // namespace rpem::analysis
