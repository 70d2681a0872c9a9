#pragma once
// A VESC-class outrunner (the 6374 of config/vesc-6374-outrunner.yaml: 7 pole pairs, 25 mΩ, 20 µH,
// ψm 4.63 mWb) with the paper's per-unit gains, restated here (not read from config/) for the tests of
// real drives' regimes: the machine issue 23's VESC Tool log came from is of this class.

#include "rpem/core/machine.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::test {

inline core::MachineSi outrunner_machine_si() {
  core::MachineSi m;
  m.rated = {34.0, 40.0, 6000.0, 7};
  m.r_s_Ohm = 0.025;
  m.psi_m_Wb = 0.004633;
  m.l_d_H = 20e-6;
  m.l_q_H = 20e-6;
  return m;
}

inline core::PerUnitBase outrunner_base() { return core::PerUnitBase::from_rated(outrunner_machine_si().rated); }

/// The paper's gain sequences at VESC's 80 µs control period, D_M ±50 % about the nominal values,
/// eq:GainSchedule at 600 rpm (ψm) and 60 rpm (r_s).
inline core::EstimatorSettings outrunner_settings(core::Algorithm algorithm = core::Algorithm::kSga) {
  core::EstimatorSettings s;
  s.algorithm = algorithm;
  s.gains[0] = {core::Vec2(6.25e-4, 6.25e-4), core::Vec2(3.25e-4, 6.25e-5)};
  s.gains[1] = {core::Vec2(6.25e-4, 6.25e-5), core::Vec2(3.25e-4, 7.5e-6)};
  s.gains[2] = {core::Vec2(0.0, 0.0), core::Vec2(3.25e-4, 6.25e-5)};
  s.floors = {1e-2, 1e-4, 1e-6, 1e-3};
  s.psi_m_min_speed_rpm = 600.0;
  s.r_s_max_speed_rpm = 60.0;
  s.psi_m_min_Wb = 0.0023;
  s.psi_m_max_Wb = 0.0070;
  s.r_s_min_Ohm = 0.0125;
  s.r_s_max_Ohm = 0.050;
  s.initial_psi_m_Wb = 0.004633;
  s.initial_r_s_Ohm = 0.025;
  s.initial_sga_hessian_pu = core::Vec2(100.0, 100.0);
  s.initial_gna_hessian_pu = core::Mat2::Identity();
  s.nominal_sample_period_s = 80e-6;
  s.max_sample_interval_s = 8 * 80e-6;
  return s;
}

}  // namespace rpem::test
