#pragma once
// The thermal network's fitted quantities as `rpem thermal fit`'s parameter vector (thermal_fit.cpp): each
// capacitance, conductance, loss coefficient and the copper loss's scale the start configuration has (a zero
// one is not in the topology and stays zero), as its logarithm, so positive by construction. Loss forms the
// training part cannot tell apart at one node are tied and fitted as one (docs/thermal.md, "What one log
// cannot tell").

#include <array>
#include <string>
#include <vector>

#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/core/thermal_network.hpp"
#include "rpem/io/thermal_config.hpp"

namespace rpem::analysis::network {

enum class SlotKind { kCapacitance, kToCoolant, kToCoolantAtSpeed, kBetween, kBetweenAtSpeed, kLoss, kCopperScale };

/// One fitted quantity.
struct Slot {
  SlotKind kind;
  int i = 0, j = 0;  ///< node(s); the (first) loss form in j for kLoss
  std::string name, unit;
  /// kLoss: every form's coefficient relative to the first's (forms the log cannot tell apart move together).
  std::array<double, core::kLossForms> share{};
};

/// Loss forms at one node that the training part cannot tell apart, fitted as one.
struct LossTie {
  int node;
  std::vector<int> forms;
  std::vector<double> share;  ///< coefficients relative to the first form's
};

/// Loss forms at one node that the training part (its first `steps` steps) cannot tell apart — the ratio of
/// their bases constant to 2 % between its 10th and 90th percentiles (one operating point; one speed for
/// hysteresis against eddy currents) — are tied: fitted as one, each carrying an equal part of their loss at
/// the training part's median operating point. Sets the coefficients of `c` (the start) so, and says so in `notes`.
[[nodiscard]] std::vector<LossTie> tie_collinear_losses(io::ThermalConfig& c, const ThermalRecord& r, std::size_t steps,
                                                        std::vector<std::string>& notes);

/// Where each fitted quantity lives in the network, and how the parameter vector maps onto a configuration.
class Layout {
 public:
  Layout(const io::ThermalConfig& start, const std::vector<LossTie>& ties);

  [[nodiscard]] const std::vector<Slot>& slots() const { return slots_; }
  [[nodiscard]] std::size_t size() const { return slots_.size(); }

  /// The parameter vector of a configuration (log values).
  [[nodiscard]] std::vector<double> values(const io::ThermalConfig& c) const;
  /// The start configuration with the parameter vector's quantities (log values, size() of them).
  [[nodiscard]] io::ThermalConfig apply(const double* x) const;
  /// A slot's value in a configuration (SI).
  [[nodiscard]] static double quantity(const io::ThermalConfig& c, const Slot& s);

 private:
  io::ThermalConfig start_;
  std::vector<Slot> slots_;
};

}  // namespace rpem::analysis::network
