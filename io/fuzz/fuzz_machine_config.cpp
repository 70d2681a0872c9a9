// libFuzzer target for the YAML configuration reader (machine, estimator and model-extension sections;
// docs/configuration.md): the input is the file's bytes. The reader must never crash and may fail only
// with ConfigError; a configuration it accepts must give an estimator that starts and, on a few samples
// of a loaded machine at speed, keeps its estimates finite and inside D_M.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rpem/core/drive_estimator.hpp"
#include "rpem/io/machine_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rpem;
  io::MachineConfig c;
  try {
    io::YamlMap root = io::YamlMap::load_string(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    c = io::parse_machine_config(root);
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
  // Inside D_M to rounding: the estimator projects in pu, and the SI value carries the conversion's rounding.
  auto inside = [](double v, double lo, double hi) {
    return std::isfinite(v) && v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
  };
  for (int k = 0; k < 16; ++k) {
    x.t_ns = 125'000LL * k;
    x.theta_el_rad = std::fmod(x.omega_el_rad_s * 125e-6 * k, 6.283185307179586);
    const core::Estimate e = estimator.step(x);
    if (!inside(e.psi_m_Wb, s.psi_m_min_Wb, s.psi_m_max_Wb) || !inside(e.r_s_Ohm, s.r_s_min_Ohm, s.r_s_max_Ohm)) {
      std::abort();
    }
  }
  return 0;
}
