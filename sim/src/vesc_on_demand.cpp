#include "rpem/sim/vesc_on_demand.hpp"

#include <algorithm>
#include <cmath>

namespace rpem::sim {

OnDemandVesc::OnDemandVesc(Scenario scenario, const Settings& settings, TruthLogWriter* truth)
    : motor_(std::move(scenario), settings.motor),
      threads_(settings.status),
      truth_(truth),
      truth_period_ns_(std::max<std::int64_t>(settings.truth_period_ns, 1)) {
  for (std::size_t k = 0; k < threads_.size(); ++k) {
    if (threads_[k].rate_Hz > 0.0) status_period_ns_[k] = std::max<std::int64_t>(std::llround(1e9 / threads_[k].rate_Hz), 1);
    next_status_ns_[k] = status_period_ns_[k];  // the threads' first sleep ends one period after start
  }
}

std::size_t OnDemandVesc::next_status_thread() const noexcept {
  std::size_t best = threads_.size();
  for (std::size_t k = 0; k < threads_.size(); ++k) {
    if (status_period_ns_[k] == 0) continue;
    if (best == threads_.size() || next_status_ns_[k] < next_status_ns_[best]) best = k;
  }
  return best;
}

bool OnDemandVesc::advance(std::int64_t t_ns) {
  if (truth_ == nullptr) return motor_.advance_to(t_ns);
  for (;;) {
    if (!motor_.advance_to(std::min(t_ns, next_truth_ns_))) return false;
    if (motor_.time_ns() >= next_truth_ns_) {
      truth_->write(motor_.truth());
      next_truth_ns_ = motor_.time_ns() + truth_period_ns_;
    }
    if (motor_.time_ns() >= t_ns) return true;
  }
}

OnDemandVesc::Read OnDemandVesc::read(bool behind) noexcept {
  Read r;
  r.behind = behind;
  r.cycles = motor_.cycles_since_read();
  r.values = motor_.read_values();
  ++counters_.reads;
  if (behind) ++counters_.behind;
  if (r.cycles == 0) ++counters_.empty_reads;
  return r;
}

}  // namespace rpem::sim
