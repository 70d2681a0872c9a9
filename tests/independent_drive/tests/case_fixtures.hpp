#pragma once
// Cases the generator's tests share: a configuration of the repository, and the switches that make a run
// noiseless and ideal so that its numbers can be checked against hand-derived answers.
#include <string>

#include "indep_drive/case.hpp"

namespace indep::testing {

inline std::string source_path(const std::string& relative) { return std::string(RPEM_TEST_SOURCE_DIR) + "/" + relative; }

inline Case machine_case(const std::string& config = "config/paper-ipmsm.yaml") {
  Case c;
  c.machine = read_machine_config(source_path(config));
  return c;
}

/// No noise, no quantisation, exact encoder, true machine = configuration.
inline Case ideal_case(const std::string& config = "config/paper-ipmsm.yaml") {
  Case c = machine_case(config);
  c.sensors.current_noise_A = 0.0;
  c.sensors.adc_bits = 0;
  c.sensors.encoder_counts_per_rev = 0;
  c.sensors.u_dc_noise_V = 0.0;
  c.sensors.u_dc_adc_bits = 0;
  c.draw.psi_m_rel = c.draw.r_s_rel = c.draw.l_d_rel = c.draw.l_q_rel = 0.0;
  return c;
}

/// Constant speed [rpm] and torque [Nm] from t = 0.
inline void hold(Case& c, double speed_rpm, double torque_Nm) { c.profile.points = {{0.0, speed_rpm, torque_Nm, 0.0}}; }

}  // namespace indep::testing
