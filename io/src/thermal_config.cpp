#include "rpem/io/thermal_config.hpp"

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include "rpem/core/non_finite.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/plausibility.hpp"
#include "rpem/core/thermal_stability.hpp"
#include "rpem/core/thermal_terms.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
namespace {

using core::kInf;

std::string num(double v) {
  std::string s;
  append_number(s, v);
  return s;
}

/// A temperature law (core/thermal.hpp) and its calibration's σ (`offset`, `coefficient`: the filter's
/// calibration states); the copper law's also gives the copper loss's scale and relative uncertainty.
core::DriftLaw parse_law(YamlMap m, const char* ref_key, core::DriftLaw law, double ref_max, bool rising,
                         core::CalibrationVec& sigma, core::Calibration offset, core::Calibration coefficient,
                         double* loss_rel_sigma, double* loss_scale) {
  law.value_ref = m.number_or(ref_key, law.value_ref, 1e-9, ref_max);
  // A reference temperature without a coefficient: the default coefficient referred to it (the same line).
  const double reference_C = m.number_or("reference_C", law.reference_C, -273.0, 500.0);
  law.coeff_per_K = law.referred_to(reference_C).coeff_per_K;
  law.reference_C = reference_C;
  law.coeff_per_K = rising ? m.number_or("coeff_per_K", law.coeff_per_K, 1e-6, 0.1)
                           : m.number_or("coeff_per_K", law.coeff_per_K, -0.1, -1e-6);
  double& s_offset = sigma[static_cast<int>(offset)];
  double& s_coefficient = sigma[static_cast<int>(coefficient)];
  s_offset = m.number_or("reference_sigma_K", s_offset, 0.0, 100.0);
  s_coefficient = m.number_or("coeff_rel_sigma", s_coefficient, 0.0, 1.0);
  if (loss_rel_sigma) *loss_rel_sigma = m.number_or("loss_rel_sigma", *loss_rel_sigma, 0.0, 10.0);
  if (loss_scale) *loss_scale = m.number_or("loss_scale", *loss_scale, 1e-3, 1e3);
  m.finish();
  return law;
}

/// σ of a law's coefficient relative to it: the spread of the material whose range holds it (core/thermal.hpp).
template <std::size_t N>
double coefficient_rel_sigma(const std::array<core::MaterialCoefficient, N>& materials, double alpha) {
  const auto m = core::material_of(materials, alpha);
  return m ? m->rel_sigma() : 0.1;
}

/// The highest temperature a law can describe: its material's (core::MaterialCoefficient::highest_C, a magnet's Curie
/// temperature) where its coefficient at the materials' reference temperature lies in one of `materials`' ranges,
/// else the plausible maximum.
template <std::size_t N>
double highest_temperature_C(const std::array<core::MaterialCoefficient, N>& materials, const core::DriftLaw& law) {
  const std::optional<core::MaterialCoefficient> m =
      core::material_of(materials, law.referred_to(core::kMaterialReference_C).coeff_per_K);
  const double plausible_C = core::PlausibleMagnitudes{}.temperature_max_C;
  return m ? std::min(plausible_C, m->highest_C) : plausible_C;
}

/// Why no value within the estimator's bounds [lo, hi] reads through the law as a temperature the machine can have
/// (absolute zero to `highest_C`, the material's highest), or nothing. Such a law is another machine's (a thermal.yaml
/// fitted with another --config): every estimate would be read as an impossible temperature. A magnet law from a
/// larger machine reads every value of a smaller one's bounds near T_ref + 1/|α| (853 °C for NdFeB), below 1 000 °C
/// but far above any NdFeB magnet's Curie temperature: only the material's limit refuses it.
std::optional<std::string> law_outside_bounds(const core::DriftLaw& law, double lo, double hi, const char* bounds_key,
                                              double highest_C) {
  const double lowest_C = core::PlausibleMagnitudes{}.temperature_min_C;
  const double a = law.temperature_C(lo), b = law.temperature_C(hi);
  if (std::max(a, b) >= lowest_C && std::min(a, b) <= highest_C) return std::nullopt;
  std::ostringstream why;
  why << std::setprecision(4) << "reads the estimator's whole range " << bounds_key << " [" << lo << ", " << hi << "] as "
      << std::min(a, b) << " to " << std::max(a, b) << " °C, outside " << lowest_C << " to " << highest_C
      << " °C (absolute zero to the "
      << (highest_C < core::PlausibleMagnitudes{}.temperature_max_C
              ? "highest Curie temperature of the magnet material its coefficient is"
              : "highest plausible temperature")
      << "): this law is not the configured machine's (a thermal.yaml fitted with another machine's configuration?)";
  return why.str();
}

}  // namespace

int node_index(const ThermalConfig& c, const std::string& name) {
  for (int i = 0; i < c.fusion.filter.network.nodes; ++i) {
    if (c.node_names[static_cast<std::size_t>(i)] == name) return i;
  }
  return -1;
}

ThermalConfig default_thermal_config(const MachineConfig& machine) {
  ThermalConfig c;
  c.has_network = false;  // the laws only: a fit gives the network
  core::ThermalNetwork& n = c.fusion.filter.network;
  n.nodes = 2;
  n.winding = 0;
  n.magnet = 1;
  c.node_names[0] = "winding";
  c.node_names[1] = "magnet";
  n.base = core::loss_base_of(core::PerUnitBase::from_rated(machine.machine.rated), machine.machine);
  n.copper = machine.rs_drift.law.value_or(core::DriftLaw{core::kCopper.typical_per_K, core::kMaterialReference_C, 0.0});
  c.copper_reference_stated = machine.rs_drift.law.has_value();
  c.magnet_law_stated = machine.psim_drift.law.has_value();
  if (n.copper.value_ref <= 0.0) n.copper.value_ref = machine.machine.r_s_Ohm;
  core::DriftLaw& m = c.fusion.magnet_law;
  m = machine.psim_drift.law.value_or(core::DriftLaw{core::kNdFeB.typical_per_K, core::kMaterialReference_C, 0.0});
  if (m.value_ref <= 0.0) m.value_ref = machine.machine.psi_m_Wb;
  core::CalibrationVec& sigma = c.fusion.filter.calibration_sigma;
  sigma[static_cast<int>(core::Calibration::kMagnetCoefficient)] =
      coefficient_rel_sigma(core::kMagnetMaterials, m.coeff_per_K);
  sigma[static_cast<int>(core::Calibration::kCopperCoefficient)] =
      coefficient_rel_sigma(core::kWindingMaterials, n.copper.coeff_per_K);
  return c;
}

namespace {

/// `nodes`: their names, capacities, coolant conductances and noises; winding and magnet among them.
void parse_nodes(YamlMap& t, ThermalConfig& c) {
  core::ThermalFusionConfig& f = c.fusion;
  core::ThermalNetwork& n = f.filter.network;
  std::vector<YamlMap> nodes = t.maps("nodes");
  if (nodes.size() < 2 || nodes.size() > static_cast<std::size_t>(core::kMaxThermalNodes)) {
    t.fail("nodes",
           "a network has 2 to " + std::to_string(core::kMaxThermalNodes) + " nodes, here " + std::to_string(nodes.size()));
  }
  n.nodes = static_cast<int>(nodes.size());
  n.winding = n.magnet = -1;
  c.node_names = {};
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    YamlMap& m = nodes[i];
    const std::string name = m.text("name");
    if (name.empty() || name == "coolant") m.fail("name", "'" + name + "' cannot name a node (coolant is the boundary)");
    for (std::size_t k = 0; k < i; ++k) {
      if (c.node_names[k] == name) m.fail("name", "node '" + name + "' appears twice");
    }
    c.node_names[i] = name;
    const int idx = static_cast<int>(i);
    if (name == "winding") n.winding = idx;
    if (name == "magnet") n.magnet = idx;
    n.capacitance_J_per_K[idx] = m.number("capacitance_J_per_K", 1e-6, 1e9);
    n.to_coolant_W_per_K[idx] = m.number_or("to_coolant_W_per_K", 0.0, 0.0, 1e6);
    // eq. 14.1b's speed part; absent: a conductance that does not change with speed.
    n.to_coolant_at_base_speed_W_per_K[idx] = m.number_or("to_coolant_at_base_speed_W_per_K", 0.0, 0.0, 1e6);
    if (i == 0) c.process_noise_stated = false;
    c.process_noise_stated = c.process_noise_stated || m.has("process_noise_K2_per_s") || m.has("disturbance_W2_per_s");
    f.filter.process_noise_K2_per_s[idx] = m.number_or("process_noise_K2_per_s", 0.0, 0.0, 1e3);
    f.filter.disturbance_W2_per_s[idx] = m.number_or("disturbance_W2_per_s", 0.0, 0.0, 1e12);
    // τ_d of eq. 14.19; absent: the random walk (τ_d = ∞).
    f.filter.disturbance_time_constant_s[idx] =
        m.number_or("disturbance_time_constant_s", std::numeric_limits<double>::infinity(), 1.0, 1e9);
    m.finish();
  }
  for (int i = n.nodes; i < core::kMaxThermalNodes; ++i) {
    n.capacitance_J_per_K[i] = 1.0;
    n.to_coolant_W_per_K[i] = 0.0;
    n.to_coolant_at_base_speed_W_per_K[i] = 0.0;
  }
  if (n.winding < 0) t.fail("nodes", "a node named 'winding' is required (the copper loss heats it, R_s follows it)");
  if (n.magnet < 0) t.fail("nodes", "a node named 'magnet' is required (ψm follows it)");
}

/// `conductances`: each joins two different nodes, once; every node must reach the coolant.
void parse_conductances(YamlMap& t, ThermalConfig& c) {
  core::ThermalNetwork& n = c.fusion.filter.network;
  n.between_W_per_K.setZero();
  n.between_at_base_speed_W_per_K.setZero();
  if (t.has("conductances")) {
    for (YamlMap& m : t.maps("conductances")) {
      const std::string from = m.text("from"), to = m.text("to");
      const int a = node_index(c, from), b = node_index(c, to);
      if (a < 0) m.fail("from", "no node named '" + from + "'");
      if (b < 0) m.fail("to", "no node named '" + to + "'");
      if (a == b) m.fail("to", "a conductance joins two different nodes");
      if (n.between_W_per_K(a, b) != 0.0)
        m.fail("to", std::string("the conductance ").append(from).append("–").append(to).append(" is given twice"));
      n.between_W_per_K(a, b) = n.between_W_per_K(b, a) = m.number("W_per_K", 1e-9, 1e6);
      // eq. 14.1b's speed part (the air gap's convection); absent: a conductance that does not change with speed.
      n.between_at_base_speed_W_per_K(a, b) = n.between_at_base_speed_W_per_K(b, a) =
          m.number_or("at_base_speed_W_per_K", 0.0, 0.0, 1e6);
      m.finish();
    }
  }
  // Every node must reach the coolant: otherwise its temperature has no steady state.
  {
    std::array<bool, core::kMaxThermalNodes> reach{};
    for (int i = 0; i < n.nodes; ++i) reach[static_cast<std::size_t>(i)] = n.to_coolant_W_per_K[i] > 0.0;
    for (int pass = 0; pass < n.nodes; ++pass) {
      for (int i = 0; i < n.nodes; ++i) {
        for (int j = 0; j < n.nodes; ++j) {
          if (n.between_W_per_K(i, j) > 0.0 && reach[static_cast<std::size_t>(j)]) reach[static_cast<std::size_t>(i)] = true;
        }
      }
    }
    for (int i = 0; i < n.nodes; ++i) {
      if (!reach[static_cast<std::size_t>(i)]) {
        t.fail("nodes", "node '" + c.node_names[static_cast<std::size_t>(i)] +
                            "' has no path of conductances to the coolant (its temperature would have no steady state)");
      }
    }
  }
}

/// `losses`: each a loss form of the catalogue at a node, once.
void parse_losses(YamlMap& t, ThermalConfig& c) {
  core::ThermalFusionConfig& f = c.fusion;
  core::ThermalNetwork& n = f.filter.network;
  n.loss_at_base_W.setZero();
  if (t.has("losses")) {
    for (YamlMap& m : t.maps("losses")) {
      const std::string form = m.text("form");
      int fi = -1;
      for (const core::LossFormRow& row : core::loss_forms()) {
        if (row.name == form) fi = static_cast<int>(row.form);
      }
      if (fi < 0) {
        std::string names;
        for (const core::LossFormRow& row : core::loss_forms()) names.append(names.empty() ? "" : ", ").append(row.name);
        m.fail("form", std::string("unknown loss form '").append(form).append("' (one of ").append(names).append(")"));
      }
      const std::string node = m.text("node");
      const int i = node_index(c, node);
      if (i < 0) m.fail("node", "no node named '" + node + "'");
      if (n.loss_at_base_W(fi, i) != 0.0)
        m.fail("node", std::string("loss ").append(form).append(" at ").append(node).append(" is given twice"));
      n.loss_at_base_W(fi, i) = m.number("at_base_W", 0.0, 1e9);
      f.filter.loss_rel_sigma(fi, i) = m.number_or("rel_sigma", 0.5, 0.0, 10.0);
      m.finish();
    }
  }
}

/// `nodes`, `conductances` and `losses`.
void parse_network(YamlMap& t, ThermalConfig& c) {
  parse_nodes(t, c);
  parse_conductances(t, c);
  parse_losses(t, c);
}

}  // namespace

ThermalConfig parse_thermal_config(YamlMap& section, const MachineConfig& machine, NetworkRequired network) {
  ThermalConfig c = default_thermal_config(machine);
  core::ThermalFusionConfig& f = c.fusion;
  core::ThermalNetwork& n = f.filter.network;
  c.has_network = network == NetworkRequired::kYes || section.has("nodes");
  if (c.has_network) {
    parse_network(section, c);
  } else {
    for (const char* key : {"conductances", "losses"}) {
      if (section.has(key)) section.fail(key, "belongs to a network: give `nodes` too");
    }
  }
  if (auto b = section.optional_map("loss_base")) {
    n.base.omega_el_rad_s = b->number_or("omega_el_rad_s", n.base.omega_el_rad_s, 1e-3, 1e7);
    n.base.psi_Wb = b->number_or("psi_Wb", n.base.psi_Wb, 1e-9, 100.0);
    n.base.current_A = b->number_or("current_A", n.base.current_A, 1e-6, 1e6);
    b->finish();
  }
  if (auto m = section.optional_map("copper")) {
    c.copper_reference_stated = c.copper_reference_stated || m->has("reference_C");
    n.copper =
        parse_law(*m, "r_s_ref_Ohm", n.copper, 1e4, true, f.filter.calibration_sigma, core::Calibration::kCopperOffset,
                  core::Calibration::kCopperCoefficient, &f.filter.copper_rel_sigma, &n.copper_scale);
  }
  c.magnet_law_stated = c.magnet_law_stated || section.has("magnet_law");
  if (auto m = section.optional_map("magnet_law")) {
    f.magnet_law = parse_law(*m, "psi_m_ref_Wb", f.magnet_law, 100.0, false, f.filter.calibration_sigma,
                             core::Calibration::kMagnetOffset, core::Calibration::kMagnetCoefficient, nullptr, nullptr);
  }
  f.coolant_C = section.number_or("coolant_C", f.coolant_C, -60.0, 300.0);
  // q_c: how fast an unread coolant may move (docs/derivations.md eq. 14.29); 0: a held reading is exact.
  f.filter.coolant_drift_K2_per_s = section.number_or("coolant_drift_K2_per_s", f.filter.coolant_drift_K2_per_s, 0.0, 1e3);
  if (auto s = section.optional_map("winding_sensor")) {
    f.winding_sensor_sigma_K = s->number("sigma_K", 1e-3, 100.0);
    // Its lag behind the winding node (docs/derivations.md eq. 14.19); 0: the reading is the node.
    f.winding_sensor_time_constant_s = s->number_or("time_constant_s", 0.0, 0.0, 3600.0);
    // What the winding node stands for (eq. 14.24): the winding (the sensor lags it) or the sensor's reading.
    f.winding_node_is_reading = s->choice_or("node", "winding", {"winding", "reading"}) == "reading";
    s->finish();
  }
  if (auto m = section.optional_map("filter")) {
    f.observer.period_s = m->number_or("period_s", f.observer.period_s, 1e-3, 3600.0);
    f.initial_sigma_K = m->number_or("initial_sigma_K", f.initial_sigma_K, 1e-3, 1000.0);
    f.filter.gate_sigma = m->number_or("gate_sigma", f.filter.gate_sigma, 1.0, kInf);
    f.filter.gate_reset_after = static_cast<int>(m->integer_or("gate_reset_after", f.filter.gate_reset_after, 0, 1000000));
    f.observer.residual_time_constant_s =
        m->number_or("residual_time_constant_s", f.observer.residual_time_constant_s, 1e-3, 3600.0);
    f.observer.settle_time_constants = m->number_or("settle_time_constants", f.observer.settle_time_constants, 0.0, 100.0);
    m->finish();
  }
  const core::EstimatorSettings& bounds = machine.estimator;
  if (auto why = law_outside_bounds(f.magnet_law, bounds.psi_m_min_Wb, bounds.psi_m_max_Wb, "estimator.bounds.psi_m_Wb",
                                    highest_temperature_C(core::kMagnetMaterials, f.magnet_law)))
    section.fail("magnet_law", "magnet_law " + *why);
  if (auto why = law_outside_bounds(n.copper, bounds.r_s_min_Ohm, bounds.r_s_max_Ohm, "estimator.bounds.r_s_Ohm",
                                    highest_temperature_C(core::kWindingMaterials, n.copper)))
    section.fail("copper", "copper law " + *why);
  if (c.has_network) {
    if (const std::optional<std::string> why = runaway_at_rating(c, machine)) section.fail("nodes", *why);
  }
  section.finish();
  return c;
}

std::optional<std::string> runaway_at_rating(const ThermalConfig& c, const MachineConfig& machine) {
  const core::ThermalNetwork& n = c.fusion.filter.network;
  const core::PerUnitBase rated = core::PerUnitBase::from_rated(machine.machine.rated);
  core::ThermalLoad load;
  load.current_sq_A2 = rated.current_A * rated.current_A;
  load.convection_basis = std::sqrt(std::abs(rated.omega_el_rad_s) / n.base.omega_el_rad_s);
  if (core::thermal_settles(n, load)) return std::nullopt;
  std::ostringstream why;
  why << std::setprecision(4) << "the network has no steady state at the machine's rated point (" << rated.current_A
      << " A peak at " << rated.omega_el_rad_s << " rad/s electrical, machine.rated): the copper loss grows by "
      << core::copper_loss_per_K(n, load)
      << " W/K with the winding's temperature (copper: loss_scale, r_s_ref_Ohm, coeff_per_K), at least the "
      << core::winding_conductance_to_coolant_W_per_K(n, load)
      << " W/K the winding conducts to the coolant through the network (directly and through the other nodes): a "
         "winding that runs away at the current it is rated to carry (docs/derivations.md, eq. 14.27)";
  return why.str();
}

std::vector<std::string> assumed_law_notes(const ThermalConfig& c, bool magnet) {
  // One law's note: the value taken, where it could have been stated, what an error of it does, the key to state it.
  const auto note = [](const char* name, const char* quantity, const core::DriftLaw& law, const char* unit,
                       const char* drift, const char* section_key, const char* consequence) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "the %s law takes %s_ref %.5g %s at %.4g °C, an assumption: neither the machine's %s nor the thermal "
                  "section's %s says at what temperature %s was measured. If it was measured hot, %s (docs/thermal.md)",
                  name, quantity, law.value_ref, unit, law.reference_C, drift, section_key, quantity, consequence);
    return std::string(text);
  };
  std::vector<std::string> notes;
  if (!c.copper_reference_stated) {
    notes.push_back(note("copper", "r_s", c.fusion.filter.network.copper, "Ohm", "rs_drift", "copper",
                         "every winding temperature r_s gives and the copper loss are off; say so with copper: "
                         "{reference_C: …}"));
  }
  if (magnet && !c.magnet_law_stated) {
    notes.push_back(note("magnet", "psi_m", c.fusion.magnet_law, "Wb", "psim_drift", "magnet_law",
                         "every magnet temperature psi_m gives is off by about the difference; give magnet_law "
                         "(`rpem thermal fit` writes it, anchored at a soaked start)"));
  }
  return notes;
}

std::string soaked_start_note(const std::string& untested_because) {
  return "the thermal network starts soaked, every node at the coolant, an assumption: " + untested_because +
         ". A machine warmer than its coolant at the start (a restart on a warm machine, a log cut from a longer run) "
         "reads a cold magnet until the observations correct it (docs/thermal.md, \"A log that does not start "
         "soaked\")";
}

std::optional<std::string> process_noise_note(const ThermalConfig& c) {
  if (!c.has_network || c.process_noise_stated) return std::nullopt;
  return std::string(
      "no node states process_noise_K2_per_s or disturbance_W2_per_s: both are 0, so the filter takes the network as "
      "exact between observations and its band holds only the start's and the observations' uncertainty — too narrow, "
      "and the estimate deaf to its observations, wherever the network is not exact. `rpem thermal fit` fits both; "
      "give them where the network was written by hand (docs/thermal.md, \"thermal.yaml\")");
}

ThermalConfig load_thermal_config(const std::string& path, const MachineConfig& machine, NetworkRequired network) {
  YamlMap root = YamlMap::load_file(path);
  YamlMap section = root.map("thermal");
  return parse_thermal_config(section, machine, network);
}

std::string thermal_config_yaml(const ThermalConfig& c) {
  const core::ThermalFusionConfig& f = c.fusion;
  const core::ThermalNetwork& n = f.filter.network;
  std::ostringstream o;
  o << "thermal:\n  nodes:\n";
  for (int i = 0; i < n.nodes; ++i) {
    o << "    - {name: " << c.node_names[static_cast<std::size_t>(i)]
      << ", capacitance_J_per_K: " << num(n.capacitance_J_per_K[i])
      << ", to_coolant_W_per_K: " << num(n.to_coolant_W_per_K[i]);
    if (n.to_coolant_at_base_speed_W_per_K[i] > 0.0)
      o << ", to_coolant_at_base_speed_W_per_K: " << num(n.to_coolant_at_base_speed_W_per_K[i]);
    o << ", process_noise_K2_per_s: " << num(f.filter.process_noise_K2_per_s[i])
      << ", disturbance_W2_per_s: " << num(f.filter.disturbance_W2_per_s[i]);
    if (std::isfinite(f.filter.disturbance_time_constant_s[i]))
      o << ", disturbance_time_constant_s: " << num(f.filter.disturbance_time_constant_s[i]);
    o << "}\n";
  }
  std::string between;
  for (int i = 0; i < n.nodes; ++i) {
    for (int j = i + 1; j < n.nodes; ++j) {
      if (n.between_W_per_K(i, j) <= 0.0) continue;
      between += "    - {from: " + c.node_names[static_cast<std::size_t>(i)] +
                 ", to: " + c.node_names[static_cast<std::size_t>(j)] + ", W_per_K: " + num(n.between_W_per_K(i, j)) +
                 (n.between_at_base_speed_W_per_K(i, j) > 0.0
                      ? ", at_base_speed_W_per_K: " + num(n.between_at_base_speed_W_per_K(i, j))
                      : std::string()) +
                 "}\n";
    }
  }
  if (!between.empty()) o << "  conductances:\n" << between;
  std::string losses;
  for (const core::LossFormRow& row : core::loss_forms()) {
    for (int i = 0; i < n.nodes; ++i) {
      const double k = n.loss_at_base_W(static_cast<int>(row.form), i);
      if (k <= 0.0) continue;
      losses += "    - {form: " + std::string(row.name) + ", node: " + c.node_names[static_cast<std::size_t>(i)] +
                ", at_base_W: " + num(k) + ", rel_sigma: " + num(f.filter.loss_rel_sigma(static_cast<int>(row.form), i)) +
                "}\n";
    }
  }
  if (!losses.empty()) o << "  losses:\n" << losses;
  o << "  loss_base: {omega_el_rad_s: " << num(n.base.omega_el_rad_s) << ", psi_Wb: " << num(n.base.psi_Wb)
    << ", current_A: " << num(n.base.current_A) << "}\n";
  const core::CalibrationVec& sigma = f.filter.calibration_sigma;
  auto s = [&](core::Calibration k) { return num(sigma[static_cast<int>(k)]); };
  o << "  copper: {r_s_ref_Ohm: " << num(n.copper.value_ref) << ", reference_C: " << num(n.copper.reference_C)
    << ", coeff_per_K: " << num(n.copper.coeff_per_K) << ", reference_sigma_K: " << s(core::Calibration::kCopperOffset)
    << ", coeff_rel_sigma: " << s(core::Calibration::kCopperCoefficient) << ", loss_scale: " << num(n.copper_scale)
    << ", loss_rel_sigma: " << num(f.filter.copper_rel_sigma) << "}\n";
  const core::DriftLaw& m = f.magnet_law;
  o << "  magnet_law: {psi_m_ref_Wb: " << num(m.value_ref) << ", reference_C: " << num(m.reference_C)
    << ", coeff_per_K: " << num(m.coeff_per_K) << ", reference_sigma_K: " << s(core::Calibration::kMagnetOffset)
    << ", coeff_rel_sigma: " << s(core::Calibration::kMagnetCoefficient) << "}\n";
  o << "  coolant_C: " << num(f.coolant_C) << "\n";
  if (f.filter.coolant_drift_K2_per_s > 0.0)
    o << "  coolant_drift_K2_per_s: " << num(f.filter.coolant_drift_K2_per_s) << "\n";
  if (f.winding_sensor_sigma_K > 0.0) {
    o << "  winding_sensor: {sigma_K: " << num(f.winding_sensor_sigma_K);
    if (f.winding_sensor_time_constant_s > 0.0) o << ", time_constant_s: " << num(f.winding_sensor_time_constant_s);
    if (f.winding_node_is_reading) o << ", node: reading";
    o << "}\n";
  }
  o << "  filter: {period_s: " << num(f.observer.period_s) << ", initial_sigma_K: " << num(f.initial_sigma_K)
    << ", gate_sigma: " << num(f.filter.gate_sigma) << ", gate_reset_after: " << f.filter.gate_reset_after
    << ", residual_time_constant_s: " << num(f.observer.residual_time_constant_s)
    << ", settle_time_constants: " << num(f.observer.settle_time_constants) << "}\n";
  return o.str();
}

}  // namespace rpem::io
