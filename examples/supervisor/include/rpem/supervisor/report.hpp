#pragma once
// The example's output line (docs/supervisor.md, "Running it"):
//     <what> <utime>: I_max <A> A | magnet T+ <°C> C -> <A> A | winding T+ <°C> C -> <A> A
// <what> is the gate's verdict on an estimate (`accepted`, `ignored (stale)`, …) or `limit` when I_max
// changes with no message (an estimate ageing out); <utime> is the estimate's (`-` where it was not
// decoded: not authentic), or the time of a `limit` line; T+ is `unknown` where no temperature is trusted.

#include <cstdint>
#include <string>

#include "rpem/supervisor/estimate_gate.hpp"
#include "rpem/supervisor/supervisor.hpp"

namespace rpem::supervisor {

[[nodiscard]] std::string verdict_line(const Received& received, const CurrentLimit& limit);
[[nodiscard]] std::string limit_line(std::int64_t now_unix_us, const CurrentLimit& limit);

}  // namespace rpem::supervisor
