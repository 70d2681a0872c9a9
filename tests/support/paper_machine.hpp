#pragma once
// The paper's machine (tab_machineData) in pu and SI, for tests. Values are restated here on purpose
// (not read from config/) so that a wrong configuration file is caught by the tests.

#include "rpem/core/machine.hpp"
#include "rpem/core/per_unit.hpp"
#include "rpem/core/settings.hpp"

namespace rpem::test {

inline core::MachineSi paper_machine_si() {
  core::MachineSi m;
  m.rated = {400.0, 4.93, 1000.0, 3};
  m.r_s_Ohm = 2.25;
  m.psi_m_Wb = 1.14;
  m.l_d_H = 0.0953;
  m.l_q_H = 0.206;
  return m;
}

/// The paper machine's base electrical speed, 1000 rpm × 3 pole pairs = 100π rad/s.
inline constexpr double kOmegaN = 100.0 * core::kPi;
/// The paper's sample period (8 kHz).
inline constexpr double kDt = 125e-6;

inline core::PerUnitBase paper_base() { return core::PerUnitBase::from_rated(paper_machine_si().rated); }

inline core::MachinePu paper_machine_pu() { return core::to_pu(paper_base(), paper_machine_si()); }

/// tab_psimgains with Section V's scheduler limits and the default floors and initial Hessians.
inline core::EstimatorSettings paper_settings(core::Algorithm algorithm = core::Algorithm::kSga) {
  core::EstimatorSettings s;
  s.algorithm = algorithm;
  s.gains[0] = {core::Vec2(6.25e-4, 6.25e-4), core::Vec2(3.25e-4, 6.25e-5)};  // SGA
  s.gains[1] = {core::Vec2(6.25e-4, 6.25e-5), core::Vec2(3.25e-4, 7.5e-6)};   // GNA
  s.gains[2] = {core::Vec2(0.0, 0.0), core::Vec2(3.25e-4, 6.25e-5)};          // PhyInt
  s.floors = {1e-2, 1e-4, 1e-6, 1e-3};
  s.psi_m_min_speed_rpm = 100.0;
  s.r_s_max_speed_rpm = 10.0;
  s.psi_m_min_Wb = 0.57;
  s.psi_m_max_Wb = 1.71;
  s.r_s_min_Ohm = 1.0;
  s.r_s_max_Ohm = 4.5;
  s.initial_psi_m_Wb = 1.14;
  s.initial_r_s_Ohm = 2.25;
  s.initial_sga_hessian_pu = core::Vec2(1.0, 1.0);
  s.initial_gna_hessian_pu = core::Mat2::Identity();
  s.nominal_sample_period_s = kDt;
  s.max_sample_interval_s = 1e-3;
  return s;
}

inline core::EstimatorConfig paper_config(core::Algorithm algorithm = core::Algorithm::kSga) {
  return core::make_estimator_config(paper_base(), paper_machine_si(), paper_settings(algorithm));
}

}  // namespace rpem::test
