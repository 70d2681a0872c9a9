#include "network_layout.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "../median.hpp"

namespace rpem::analysis::network {
namespace {

/// The median of a form's basis over the training part's steps with a load.
double median_basis(const ThermalRecord& r, std::size_t steps, int form) {
  std::vector<double> b;
  for (std::size_t k = 0; k < steps; ++k) {
    const double v = r.steps[k].load.basis[static_cast<std::size_t>(form)];
    if (v > 0.0) b.push_back(v);
  }
  return median(std::move(b));
}

}  // namespace

std::vector<LossTie> tie_collinear_losses(io::ThermalConfig& c, const ThermalRecord& r, std::size_t steps,
                                          std::vector<std::string>& notes) {
  core::ThermalNetwork& n = c.fusion.filter.network;
  const auto& forms = core::loss_forms();
  auto collinear = [&](int f, int g) {
    std::vector<double> ratio;
    double largest = 0.0;
    for (std::size_t k = 0; k < steps; ++k) largest = std::max(largest, r.steps[k].load.basis[static_cast<std::size_t>(f)]);
    for (std::size_t k = 0; k < steps; ++k) {
      const auto& b = r.steps[k].load.basis;
      if (b[static_cast<std::size_t>(f)] > 1e-3 * largest)
        ratio.push_back(b[static_cast<std::size_t>(g)] / b[static_cast<std::size_t>(f)]);
    }
    if (ratio.size() < 3) return false;
    std::sort(ratio.begin(), ratio.end());
    const double p10 = ratio[ratio.size() / 10], p90 = ratio[ratio.size() * 9 / 10], mid = ratio[ratio.size() / 2];
    return mid > 0.0 && (p90 - p10) / mid < 0.02;
  };
  std::vector<LossTie> ties;
  for (int i = 0; i < n.nodes; ++i) {
    std::array<bool, core::kLossForms> used{};
    for (int f = 0; f < core::kLossForms; ++f) {
      if (used[static_cast<std::size_t>(f)] || n.loss_at_base_W(f, i) <= 0.0) continue;
      LossTie t{i, {f}, {1.0}};
      for (int g = f + 1; g < core::kLossForms; ++g) {
        if (!used[static_cast<std::size_t>(g)] && n.loss_at_base_W(g, i) > 0.0 && collinear(f, g)) {
          t.forms.push_back(g);
          used[static_cast<std::size_t>(g)] = true;
        }
      }
      if (t.forms.size() < 2) continue;
      double total = 0.0;
      std::string names;
      for (int g : t.forms) {
        total += n.loss_at_base_W(g, i) * median_basis(r, steps, g);
        names += (names.empty() ? "" : ", ") + std::string(forms[static_cast<std::size_t>(g)].name);
      }
      const double each = total / static_cast<double>(t.forms.size());
      for (int g : t.forms) n.loss_at_base_W(g, i) = each / std::max(median_basis(r, steps, g), 1e-12);
      t.share.clear();
      for (int g : t.forms) t.share.push_back(n.loss_at_base_W(g, i) / n.loss_at_base_W(f, i));
      notes.push_back(names + " at " + c.node_names[static_cast<std::size_t>(i)] +
                      " cannot be told apart on the training part (their bases keep one ratio): fitted as one loss, "
                      "each an equal part of it at the training part's median operating point");
      ties.push_back(t);
    }
  }
  return ties;
}

Layout::Layout(const io::ThermalConfig& start, const std::vector<LossTie>& ties) : start_(start) {
  const core::ThermalNetwork& n = start.fusion.filter.network;
  auto name = [&](int i) { return start.node_names[static_cast<std::size_t>(i)]; };
  for (int i = 0; i < n.nodes; ++i) slots_.push_back({SlotKind::kCapacitance, i, 0, "C " + name(i), "J/K"});
  slots_.push_back({SlotKind::kCopperScale, n.winding, 0, "copper loss scale", "1"});
  for (int i = 0; i < n.nodes; ++i) {
    if (n.to_coolant_W_per_K[i] > 0.0) slots_.push_back({SlotKind::kToCoolant, i, 0, "G " + name(i) + "–coolant", "W/K"});
    if (n.to_coolant_at_base_speed_W_per_K[i] > 0.0)
      slots_.push_back({SlotKind::kToCoolantAtSpeed, i, 0, "G " + name(i) + "–coolant at base speed (eq. 14.1b)", "W/K"});
  }
  for (int i = 0; i < n.nodes; ++i) {
    for (int j = i + 1; j < n.nodes; ++j) {
      if (n.between_W_per_K(i, j) > 0.0) slots_.push_back({SlotKind::kBetween, i, j, "G " + name(i) + "–" + name(j), "W/K"});
      if (n.between_W_per_K(i, j) > 0.0 && n.between_at_base_speed_W_per_K(i, j) > 0.0)
        slots_.push_back(
            {SlotKind::kBetweenAtSpeed, i, j, "G " + name(i) + "–" + name(j) + " at base speed (eq. 14.1b)", "W/K"});
    }
  }
  const auto& forms = core::loss_forms();
  for (int i = 0; i < n.nodes; ++i) {
    std::array<bool, core::kLossForms> done{};
    for (const LossTie& t : ties) {
      if (t.node != i) continue;
      Slot s{SlotKind::kLoss, i, t.forms.front(), "", "W", {}};
      for (std::size_t k = 0; k < t.forms.size(); ++k) {
        s.share[static_cast<std::size_t>(t.forms[k])] = t.share[k];
        s.name += (k ? "+" : "") + std::string(forms[static_cast<std::size_t>(t.forms[k])].name);
        done[static_cast<std::size_t>(t.forms[k])] = true;
      }
      s.name += " at " + name(i);
      slots_.push_back(s);
    }
    for (int f = 0; f < core::kLossForms; ++f) {
      if (done[static_cast<std::size_t>(f)] || n.loss_at_base_W(f, i) <= 0.0) continue;
      Slot s{SlotKind::kLoss, i, f, std::string(forms[static_cast<std::size_t>(f)].name) + " at " + name(i), "W", {}};
      s.share[static_cast<std::size_t>(f)] = 1.0;
      slots_.push_back(s);
    }
  }
}

std::vector<double> Layout::values(const io::ThermalConfig& c) const {
  std::vector<double> x;
  for (const Slot& s : slots_) x.push_back(std::log(quantity(c, s)));
  return x;
}

io::ThermalConfig Layout::apply(const double* x) const {
  io::ThermalConfig c = start_;
  core::ThermalNetwork& n = c.fusion.filter.network;
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    const Slot& s = slots_[k];
    const double v = std::exp(x[k]);
    switch (s.kind) {
      case SlotKind::kCapacitance:
        n.capacitance_J_per_K[s.i] = v;
        break;
      case SlotKind::kCopperScale:
        n.copper_scale = v;
        break;
      case SlotKind::kToCoolant:
        n.to_coolant_W_per_K[s.i] = v;
        break;
      case SlotKind::kToCoolantAtSpeed:
        n.to_coolant_at_base_speed_W_per_K[s.i] = v;
        break;
      case SlotKind::kBetween:
        n.between_W_per_K(s.i, s.j) = n.between_W_per_K(s.j, s.i) = v;
        break;
      case SlotKind::kBetweenAtSpeed:
        n.between_at_base_speed_W_per_K(s.i, s.j) = n.between_at_base_speed_W_per_K(s.j, s.i) = v;
        break;
      case SlotKind::kLoss:
        for (int f = 0; f < core::kLossForms; ++f) {
          if (s.share[static_cast<std::size_t>(f)] > 0.0)
            n.loss_at_base_W(f, s.i) = v * s.share[static_cast<std::size_t>(f)];
        }
        break;
    }
  }
  return c;
}

double Layout::quantity(const io::ThermalConfig& c, const Slot& s) {
  const core::ThermalNetwork& n = c.fusion.filter.network;
  switch (s.kind) {
    case SlotKind::kCapacitance:
      return n.capacitance_J_per_K[s.i];
    case SlotKind::kCopperScale:
      return n.copper_scale;
    case SlotKind::kToCoolant:
      return n.to_coolant_W_per_K[s.i];
    case SlotKind::kToCoolantAtSpeed:
      return n.to_coolant_at_base_speed_W_per_K[s.i];
    case SlotKind::kBetween:
      return n.between_W_per_K(s.i, s.j);
    case SlotKind::kBetweenAtSpeed:
      return n.between_at_base_speed_W_per_K(s.i, s.j);
    case SlotKind::kLoss:
      return n.loss_at_base_W(s.j, s.i);  // the first form's
  }
  return 0.0;
}

}  // namespace rpem::analysis::network
