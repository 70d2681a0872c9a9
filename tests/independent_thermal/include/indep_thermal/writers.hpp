#pragma once
// The output files (README.md, "Outputs"): the drive log (docs/drive-log.md, rotor-frame columns, plus the
// optional T_coolant; or the averaged log), the truth CSV (one row per log row) and the parameters JSON.
// Rows are written one at a time (generator.hpp's sink).
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "indep_thermal/generator.hpp"

namespace indep_thermal {

struct LogColumns {
  bool coolant = true;         // T_coolant [°C]
  bool winding_sensor = true;  // T_winding [°C]
  bool averaged = false;       // the averaged log: t_start after t, and window means (Case::averaged)
};

/// The drive log's header for these columns.
std::vector<std::string> log_header(LogColumns columns);
/// The truth CSV's header.
const std::vector<std::string>& truth_header();

void write_log_header(std::ostream& out, LogColumns columns);
void write_log_row(std::ostream& out, const Row& row, LogColumns columns);
void write_truth_header(std::ostream& out);
void write_truth_row(std::ostream& out, const Row& row);
/// Header and every kept row.
void write_log_csv(std::ostream& out, const Result& result, LogColumns columns);
void write_truth_csv(std::ostream& out, const Result& result);
/// Every parameter (true and nominal), the derived quantities, the laws, and a summary of the run.
nlohmann::json parameters_json(const Case& c, const Result& result, LogColumns columns);

/// Shortest decimal that reads back to the same double.
std::string shortest(double x);

}  // namespace indep_thermal
