#pragma once
// How the temperature-sensitive parameters drift with temperature — the one law every layer uses: the
// simulator's plant, the configuration's rs_drift / psim_drift (docs/model-extensions.md), the fits of
// `rpem diagnose` and rpemd's temperature derivation:
//
//   value(T) = value_ref·(1 + α·(T − T_ref))          (linear temperature coefficient α [1/K])
//   T(value) = T_ref + (value/value_ref − 1)/α        (its inverse: rpemd's temperature from an estimate)
//
// and the materials' coefficients, in one place. Copper: α = +0.393 %/K at 20 °C (IEC 60028, annealed
// copper, 0.00393 /K), taken ±15 % for alloys and for the reference temperature's effect on α. Magnets:
// the reversible temperature coefficient of remanence, which ψm follows — sintered NdFeB −0.08…−0.13 %/K,
// SmCo −0.03…−0.05 %/K, hard ferrite −0.18…−0.22 %/K (manufacturers' data sheets; docs/diagnose.md).

#include <array>
#include <optional>
#include <string_view>

namespace rpem::core {

/// The temperature the materials' coefficients below refer to (α relative to the value there), and the
/// reference of a drift law unless it names another.
inline constexpr double kMaterialReference_C = 20.0;

/// A parameter's linear drift with temperature.
struct DriftLaw {
  double coeff_per_K = 0.0;  ///< α, relative to the value at reference_C [1/K]
  double reference_C = kMaterialReference_C;
  double value_ref = 0.0;  ///< the value at reference_C in SI (Ω or Wb); 0: the machine's configured value

  /// value(T)/value_ref.
  [[nodiscard]] constexpr double factor(double t_C) const noexcept { return 1.0 + coeff_per_K * (t_C - reference_C); }
  /// value(T) (value_ref must be set).
  [[nodiscard]] constexpr double at(double t_C) const noexcept { return value_ref * factor(t_C); }
  /// The temperature at which the parameter has `value` (needs α ≠ 0 and value_ref set).
  [[nodiscard]] constexpr double temperature_C(double value) const noexcept {
    return reference_C + (value / value_ref - 1.0) / coeff_per_K;
  }
  /// The same law about another reference temperature (value_ref moves along the line, α is rescaled
  /// so the line stays the same).
  [[nodiscard]] constexpr DriftLaw referred_to(double t_C) const noexcept {
    const double f = factor(t_C);
    return {coeff_per_K / f, t_C, value_ref * f};
  }
};

/// A material's range of temperature coefficients [1/K], relative to the value at kMaterialReference_C.
struct MaterialCoefficient {
  std::string_view material;
  double typical_per_K;
  double min_per_K;
  double max_per_K;
  /// The highest temperature at which the material is what its law describes [°C]: a magnet's Curie temperature,
  /// the highest among its grades (above it the magnet holds no magnetisation); for copper, which melts only at
  /// 1 085 °C, the plausible maximum of every temperature (plausibility.hpp).
  double highest_C;
  [[nodiscard]] constexpr bool contains(double alpha) const noexcept { return alpha >= min_per_K && alpha <= max_per_K; }
  /// σ of α relative to the typical value, for a prior centred on it (eq. 14.11a): the larger of the range's
  /// uniform spread (max − min)/√12 and half the typical value's distance to the range's farther end, so that
  /// ±2σ holds every coefficient of the material's range also where the typical value is off its centre.
  [[nodiscard]] constexpr double rel_sigma() const noexcept {
    const double typical = typical_per_K < 0.0 ? -typical_per_K : typical_per_K;
    const double uniform = (max_per_K - min_per_K) / 3.4641016151377544;
    const double below = typical_per_K - min_per_K, above = max_per_K - typical_per_K;
    const double far_end = below > above ? below : above;
    return (uniform > 0.5 * far_end ? uniform : 0.5 * far_end) / typical;
  }
};

// Curie temperatures: Nd₂Fe₁₄B 310–400 °C (312 °C pure; cobalt and dysprosium raise it), SmCo₅ 720 °C and Sm₂Co₁₇
// 800–920 °C, strontium and barium ferrite 450–470 °C (J. M. D. Coey, "Magnetism and Magnetic Materials", 2010, ch. 11;
// magnet makers' tables). The highest of each family's range is taken.
inline constexpr MaterialCoefficient kCopper{"copper", 0.00393, 0.00393 * 0.85, 0.00393 * 1.15, 1000.0};
inline constexpr MaterialCoefficient kNdFeB{"NdFeB", -0.0012, -0.0013, -0.0008, 400.0};
inline constexpr MaterialCoefficient kSmCo{"SmCo", -0.0004, -0.0005, -0.0003, 920.0};
inline constexpr MaterialCoefficient kFerrite{"ferrite", -0.002, -0.0022, -0.0018, 470.0};
/// Winding materials (what R_s follows) and magnet materials (what ψm follows).
inline constexpr std::array<MaterialCoefficient, 1> kWindingMaterials{kCopper};
inline constexpr std::array<MaterialCoefficient, 3> kMagnetMaterials{kNdFeB, kSmCo, kFerrite};

/// The machine's thermal model: stator resistance against the winding temperature, magnet flux linkage
/// against the magnet temperature. The defaults are a copper winding and NdFeB magnets.
struct ThermalModel {
  DriftLaw r_s{kCopper.typical_per_K, kMaterialReference_C, 0.0};
  DriftLaw psi_m{kNdFeB.typical_per_K, kMaterialReference_C, 0.0};
};

/// The material whose range holds α, if any.
template <std::size_t N>
[[nodiscard]] constexpr std::optional<MaterialCoefficient> material_of(const std::array<MaterialCoefficient, N>& materials,
                                                                       double alpha) noexcept {
  for (const MaterialCoefficient& m : materials) {
    if (m.contains(alpha)) return m;
  }
  return std::nullopt;
}

}  // namespace rpem::core
