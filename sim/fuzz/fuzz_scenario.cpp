// libFuzzer target for the scenario reader (`rpem sim --scenario`, rpemd's simulated source;
// docs/scenarios.md): the input is the file's bytes. The reader must never crash and may fail only with
// io::InputError (ConfigError, or a data file it names that cannot be read). Paths in the input resolve
// from a directory that does not exist; inputs naming device, proc or sys files are skipped (reading
// /dev/zero would never end — a user's own choice, not the reader's defect).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rpem/sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (const char* skip : {"dev", "proc", "sys", "\\"}) {
    if (text.find(skip) != std::string::npos) return 0;
  }
  try {
    const rpem::sim::Scenario s = rpem::sim::parse_scenario(text, "fuzz.yaml", "/nonexistent-rpem-fuzz");
    if (!(s.duration_s > 0.0 && s.sample_period_s > 0.0 && s.plant_step_s > 0.0)) std::abort();
  } catch (const rpem::io::InputError&) {
  }
  return 0;
}
