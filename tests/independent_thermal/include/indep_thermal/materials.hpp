#pragma once
// Temperature laws of the materials (README.md, "Materials").
//   Copper: resistivity linear in temperature, ρ(T) ∝ 1/α20 − 20 °C + T (234.5 °C + T for annealed copper,
//   α20 = 3.93e-3/K: Dellinger 1911), so R(T) = R_ref·(K + T)/(K + T_R), K = 1/α20 − 20, T_R the
//   reference temperature of R_ref.
//   NdFeB: remanence Br(T) = Br20·(1 + α_B·(T − 20)) with α_B the reversible coefficient at 20 °C
//   (−0.09 … −0.12 %/K); ψm ∝ Br at a fixed working point: ψm(T) = ψm_ref·(1 + α_B(T − 20))/(1 + α_B(T_ψ − 20)),
//   T_ψ the reference temperature of ψm_ref.
#include "indep_thermal/parameters.hpp"

namespace indep_thermal {

/// DC resistance of the winding at T [Ω].
double copper_resistance_Ohm(const Parameters& p, double t_winding_C);
/// R_ac/R_dc at electrical frequency f: 1 + k_ac·(f/f_n)² (skin and proximity effect, low-frequency limit).
double ac_resistance_factor(const Parameters& p, double f_el_Hz);
/// Magnet flux linkage at T [Wb].
double magnet_flux_Wb(const Parameters& p, double t_magnet_C);

}  // namespace indep_thermal
