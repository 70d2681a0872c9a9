#pragma once
// The three ways a run can be refused, one per exit code of the CLI (64 usage, 65 data, 78 configuration,
// the sysexits codes rpem's tools use too). Each message names where and why.
#include <stdexcept>

namespace indep_thermal {

/// A bad option or parameter value (exit 64).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A bad profile file (exit 65): `file:line:column: reason`.
struct DataError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A configuration that cannot be used (exit 78): `file:line: machine.key: reason`.
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace indep_thermal
