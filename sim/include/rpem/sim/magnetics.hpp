#pragma once
// The plant's magnetics: constant inductances, or a measured flux map with cross-saturation.
//   constant:  ψ_d = L_d·i_d + ψ_m,          ψ_q = L_q·i_q
//   flux map:  ψ_d = ψ_d,map(i_d, i_q) + (ψ_m − ψ_m,map),  ψ_q = ψ_q,map(i_d, i_q)
// where ψ_m,map = ψ_d,map(0, 0), so a magnet-temperature change shifts the d-axis map.

#include <memory>

#include "rpem/core/types.hpp"
#include "rpem/sim/flux_map.hpp"

namespace rpem::sim {

/// The plant's true electrical parameters at one instant (SI).
struct PlantParameters {
  double r_s_Ohm = 0.0;
  double psi_m_Wb = 0.0;
  double l_d_H = 0.0;  ///< used by the constant-inductance magnetics only
  double l_q_H = 0.0;
  double r_fe_Ohm = 0.0;  ///< iron-loss resistance in parallel with the induced voltage; 0: none
};

class Magnetics {
 public:
  /// Constant inductances, read from PlantParameters at each call.
  Magnetics() = default;
  explicit Magnetics(std::shared_ptr<const FluxMap> map) : map_(std::move(map)) {}

  [[nodiscard]] bool uses_map() const noexcept { return static_cast<bool>(map_); }
  [[nodiscard]] const FluxMap* map() const noexcept { return map_.get(); }

  /// Caches what depends on the parameters (call whenever they change, before flux()/current()).
  void prepare(const PlantParameters& p) noexcept;

  [[nodiscard]] core::Vec2 flux(const core::Vec2& i_A) const noexcept;
  /// Inverse of flux(): Newton iterations from `guess` (the previous current), exact for constant L.
  [[nodiscard]] core::Vec2 current(const core::Vec2& psi_Wb, const core::Vec2& guess) const noexcept;

 private:
  std::shared_ptr<const FluxMap> map_;
  double psi_m_Wb_ = 0.0;
  double l_d_H_ = 1.0, l_q_H_ = 1.0;
  double inv_l_d_ = 1.0, inv_l_q_ = 1.0;
  double map_shift_Wb_ = 0.0;  ///< ψ_m − ψ_m,map
};

}  // namespace rpem::sim
