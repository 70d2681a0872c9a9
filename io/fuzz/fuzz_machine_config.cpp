// libFuzzer target for the YAML configuration reader (machine, estimator and model-extension sections;
// docs/configuration.md; and the thermal section as rpemd reads it inline, docs/thermal.md): the input is the
// file's bytes. The reader must never crash and may fail only with ConfigError; a configuration it accepts must
// give an estimator that starts and, on a few samples of a loaded machine at speed, keeps its estimates finite
// and inside D_M; and its thermal fusion, fed those estimates over four of its steps, temperatures and σ finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>

#include "estimate_in_bounds.hpp"
#include "rpem/core/drive_estimator.hpp"
#include "rpem/core/thermal_fusion.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/thermal_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rpem;
  io::MachineConfig c;
  std::optional<io::ThermalConfig> thermal;
  try {
    io::YamlMap root = io::YamlMap::load_string(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    c = io::parse_machine_config(root);
    if (root.has("thermal")) {  // as rpemd reads it (daemon/src/daemon_config.cpp): the network required
      io::YamlMap t = root.map("thermal");
      thermal = io::parse_thermal_config(t, c);
    }
    root.finish();
  } catch (const io::ConfigError&) {
    return 0;
  }
  const core::EstimatorSettings& s = c.estimator;
  if (!(s.psi_m_min_Wb < s.psi_m_max_Wb && s.r_s_min_Ohm < s.r_s_max_Ohm)) std::abort();
  core::DriveEstimator estimator(c.machine, s);
  const core::PerUnitBase base = core::PerUnitBase::from_rated(c.machine.rated);
  core::DriveSample x;
  x.voltage_frame = x.current_frame = core::Frame::kDq;
  x.omega_el_rad_s = 0.3 * base.omega_el_rad_s;
  x.u_dc_V = 2.0 * base.voltage_V;
  x.u_V = {-0.1 * base.voltage_V, 0.4 * base.voltage_V, 0.0};
  x.i_A = {-0.1 * base.current_A, 0.4 * base.current_A, 0.0};
  std::optional<core::ThermalFusion> fusion;
  if (thermal) fusion.emplace(thermal->fusion, estimator.base(), c.machine);
  core::ThermalSample heat;
  if (thermal) heat.dt_s = thermal->fusion.observer.period_s / 4.0;  // 16 samples: four of the filter's steps
  for (int k = 0; k < 16; ++k) {
    x.t_ns = 125'000LL * k;
    x.theta_el_rad = std::fmod(x.omega_el_rad_s * 125e-6 * k, 6.283185307179586);
    const core::Estimate e = estimator.step(x);
    if (!fuzz::estimate_in_bounds(e, s)) std::abort();
    if (fusion) {
      heat.winding_sensor_C = k % 2 == 0 ? 60.0 : std::nan("");  // a reading on every other sample
      fusion->step(e, heat);
    }
  }
  if (fusion) {
    const core::ThermalEstimate& t = fusion->estimate();
    if (!t.started) std::abort();
    for (int n = 0; n < t.nodes; ++n) {
      const core::ThermalNodeEstimate& node = t.node[static_cast<std::size_t>(n)];
      if (!std::isfinite(node.t_C) || !std::isfinite(node.sigma_K) || node.sigma_K < 0.0) std::abort();
    }
  }
  return 0;
}
