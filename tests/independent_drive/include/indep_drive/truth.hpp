#pragma once
// What the generator hid, in physical terms any model form can be compared with (README "Truth file").
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "indep_drive/case.hpp"
#include "indep_drive/machine_config.hpp"

namespace indep {

struct EffectTruth {
  std::string name;
  std::string form;  // the equation used, in words
  std::vector<std::pair<std::string, double>> values;
  std::vector<std::pair<std::string, std::string>> labels;
  [[nodiscard]] double value(const std::string& key) const;  // throws std::out_of_range
};

struct Truth {
  std::string config_path;
  MachineParams configured;
  MachineParams true_machine;  // at t = 0 (the drifts' reference temperatures)
  std::uint64_t seed = 0;
  double duration_s = 0, control_period_s = 0, switching_frequency_Hz = 0, u_dc_V = 0;
  std::string modulation;
  double initial_theta_rad = 0;
  SensorSettings noise;
  ThermalSettings thermal;
  double max_current_A = 0;          // largest true |i| at the samples
  std::vector<EffectTruth> effects;  // the hidden ones, catalogue order
  [[nodiscard]] const EffectTruth* effect(const std::string& name) const;
};

/// The truth as JSON (README "Truth file" gives the schema).
std::string truth_json(const Truth& t);

}  // namespace indep
