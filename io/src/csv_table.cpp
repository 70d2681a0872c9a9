#include "rpem/io/csv_table.hpp"
#include "rpem/io/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

namespace rpem::io {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string cell = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto first = cell.find_first_not_of(" \t\r\"");
    const auto last = cell.find_last_not_of(" \t\r\"");
    cells.push_back(first == std::string::npos ? std::string() : cell.substr(first, last - first + 1));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cells;
}

}  // namespace

template <typename IsText>
CsvTable CsvTable::read_with(const std::string& path, bool allow_nan, IsText is_text) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, 0, "", "cannot open file");
  CsvTable t;
  t.path_ = path;
  std::string line;
  if (!std::getline(in, line)) throw DataError(path, 1, 0, "", "empty file: expected a header row");
  t.header_ = split(line);
  t.columns_.resize(t.header_.size());
  std::vector<bool> text(t.header_.size(), false);
  for (std::size_t c = 0; c < t.header_.size(); ++c) text[c] = is_text(t.header_[c]);
  std::size_t line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto cells = split(line);
    if (cells.size() != t.header_.size()) {
      throw DataError(path, line_no, 0, "",
                      "row has " + std::to_string(cells.size()) + " cells, header has " + std::to_string(t.header_.size()));
    }
    for (std::size_t c = 0; c < cells.size(); ++c) {
      double v = std::nan("");
      if (!text[c]) {
        const std::string& s = cells[c];
        const NumberText read = read_number(s);
        if (read.kind != NumberText::Kind::kNumber) {
          throw DataError(path, line_no, c + 1, "column " + t.header_[c], read.reason(s));
        }
        v = read.value;
        if (std::isnan(v) && !allow_nan) throw DataError(path, line_no, c + 1, "column " + t.header_[c], "NaN");
        if (std::isinf(v)) throw DataError(path, line_no, c + 1, "column " + t.header_[c], "not finite");
      }
      t.columns_[c].push_back(v);
    }
    ++t.rows_;
    t.row_lines_.push_back(line_no);
  }
  return t;
}

CsvTable CsvTable::read(const std::string& path, bool allow_nan, const std::vector<std::string>& text_columns) {
  return read_with(path, allow_nan, [&](const std::string& name) {
    return std::find(text_columns.begin(), text_columns.end(), name) != text_columns.end();
  });
}

CsvTable CsvTable::read_numeric(const std::string& path, const std::vector<std::string>& numeric_columns) {
  return read_with(path, false, [&](const std::string& name) {
    return std::find(numeric_columns.begin(), numeric_columns.end(), name) == numeric_columns.end();
  });
}

bool CsvTable::has(const std::string& name) const {
  return std::find(header_.begin(), header_.end(), name) != header_.end();
}

const std::vector<double>& CsvTable::column(const std::string& name) const {
  const auto it = std::find(header_.begin(), header_.end(), name);
  if (it == header_.end()) throw DataError(path_, 1, 0, "column " + name, "required column is missing");
  return columns_[static_cast<std::size_t>(it - header_.begin())];
}

void CsvTable::require_increasing(const std::string& name) const {
  const std::vector<double>& v = column(name);
  const std::size_t c = static_cast<std::size_t>(std::find(header_.begin(), header_.end(), name) - header_.begin()) + 1;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k]))
      throw DataError(path_, row_lines_[k], c, "column " + name, "NaN: a time is needed on every row");
    if (k > 0 && v[k] <= v[k - 1]) {
      throw DataError(path_, row_lines_[k], c, "column " + name,
                      "does not increase (" + std::to_string(v[k]) + " after " + std::to_string(v[k - 1]) + ")");
    }
  }
}

}  // namespace rpem::io
