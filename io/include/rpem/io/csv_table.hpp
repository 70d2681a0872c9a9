#pragma once
// A small numeric CSV table (data files such as flux maps and bench profiles): a header row and
// numeric cells. Every problem throws InputError with file, line and column: DataError for the content (exit 65),
// InputError where the file cannot be opened.

#include <string>
#include <vector>

#include "rpem/io/errors.hpp"

namespace rpem::io {

class CsvTable {
 public:
  /// Reads `path`. Non-numeric cells are errors unless their column is listed in `text_columns`
  /// (those read as NaN). "nan" cells are accepted only when `allow_nan` is true.
  static CsvTable read(const std::string& path, bool allow_nan = false, const std::vector<std::string>& text_columns = {});
  /// Reads `path` for `numeric_columns` alone: every other column is text (read as NaN), whatever it holds.
  static CsvTable read_numeric(const std::string& path, const std::vector<std::string>& numeric_columns);

  [[nodiscard]] bool has(const std::string& name) const;
  /// The column's values; throws DataError naming the file if it is missing.
  [[nodiscard]] const std::vector<double>& column(const std::string& name) const;
  /// Throws DataError at the first row whose value in column `name` is NaN or not above the row before's (a time).
  void require_increasing(const std::string& name) const;
  [[nodiscard]] std::size_t rows() const noexcept { return rows_; }
  [[nodiscard]] const std::vector<std::string>& header() const noexcept { return header_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  /// `is_text(name)`: the column's cells are not read.
  template <typename IsText>
  static CsvTable read_with(const std::string& path, bool allow_nan, IsText is_text);

  std::string path_;
  std::vector<std::string> header_;
  std::vector<std::vector<double>> columns_;
  std::size_t rows_ = 0;
  std::vector<std::size_t> row_lines_;  ///< each row's line in the file (blank lines skipped)
};

}  // namespace rpem::io
