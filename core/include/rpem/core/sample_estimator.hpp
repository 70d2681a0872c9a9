#pragma once
// What an estimator of drive samples is to whoever owns it (rpemd's loop, the offline tools): it is made
// from the machine and the settings, steps one sample of its kind at a time (its Sample) into SI and pu
// estimates, and takes a supervisor's commands. DriveEstimator (phase samples at the control rate) and
// AveragedDriveEstimator (averaged rotor-frame samples at their own timestamps) are the two; rpemd's
// LoopEstimator requires it of each estimator it may hold.

#include <concepts>
#include <type_traits>

#include "rpem/core/averaged_estimator.hpp"
#include "rpem/core/drive_estimator.hpp"

namespace rpem::core {

template <class E>
concept SampleEstimator = std::is_nothrow_constructible_v<E, const MachineSi&, const EstimatorSettings&> &&
    requires(E& e, const E& c, const typename E::Sample& sample, const MachineSi& machine, const EstimatorSettings& settings,
             double value, bool frozen) {
  { e.step(sample) }
  noexcept->std::same_as<Estimate>;  ///< real-time safe
  { e.reset() }
  noexcept;
  { e.resynchronize() }
  noexcept->std::same_as<bool>;  ///< whether the previous sample's adaptation was taken back
  { e.set_frozen(frozen) }
  noexcept;
  { e.set_estimates(value, value) }
  noexcept;
  { e.reconfigure(machine, settings) }
  noexcept;
  { c.psi_m_Wb() }
  noexcept->std::same_as<double>;
  { c.r_s_Ohm() }
  noexcept->std::same_as<double>;
  { c.core() }
  noexcept->std::same_as<const RpemEstimator&>;
  { c.base() }
  noexcept->std::same_as<const PerUnitBase&>;
};

static_assert(SampleEstimator<DriveEstimator>);
static_assert(SampleEstimator<AveragedDriveEstimator>);

}  // namespace rpem::core
