#pragma once
// The one CSV reader of drive data (docs/drive-log.md): reads a file as a LogMap describes it — our drive
// log, our averaged log, VESC Tool's realtime log, a user's map — and delivers each row's quantities in SI
// with its time in integer nanoseconds. Every cell is checked where it is read: a number, finite, within
// the plausibility limits of its quantity (DriveLogLimits), a voltage command within 2·u_dc of its row;
// time increasing (after the map's wrap and tie rules). Every problem throws DriveLogError naming the file,
// line and column. Consumers (DriveLogReader, read_averaged_log) turn rows into samples.

#include <array>
#include <cstdint>
#include <deque>
#include <fstream>
#include <istream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rpem/io/errors.hpp"
#include "rpem/io/log_limits.hpp"
#include "rpem/io/log_map.hpp"

namespace rpem::io {

struct MappedRow {
  std::int64_t t_ns = 0;
  /// SI values by Quantity; NaN where the quantity is absent (or, for a nan cell its format allows, not reported).
  std::array<double, kQuantityCount> value{};
  std::size_t line = 0;  ///< the file's line the row came from
  [[nodiscard]] double operator[](Quantity q) const noexcept { return value[static_cast<std::size_t>(q)]; }
};

/// What the reader repaired or left out while reading (for the tools' summary lines).
struct ReadRepairs {
  std::uint64_t wraps = 0;      ///< the time column wrapped (ms_today at midnight)
  std::uint64_t tied_rows = 0;  ///< rows that shared their stamp with the row before, spread over its resolution
  /// The file's last line, cut off while the file was written (0: none): not read (MappedLogReader::cut_off).
  std::size_t cut_line = 0;
  /// Columns the header names, optional in the map, that hold no value on any row: read as absent (a logger that
  /// prints a format's whole header but leaves the cells of what it does not read empty).
  std::vector<std::string> never_recorded;
  /// A column's cells that held its no-reading value (MappedColumn::no_reading): no reading on their rows.
  struct NoReading {
    std::string column;      ///< the column's label
    std::string value;       ///< the value with the map's unit ("-100 degC")
    std::uint64_t rows = 0;  ///< rows read with it
    bool every_row = false;  ///< no row holds anything else (but empty cells): the column is read as absent
  };
  std::vector<NoReading> no_reading;
};

class MappedLogReader {
 public:
  MappedLogReader(const std::string& path, LogMap map, DriveLogLimits limits = {});
  /// Reads from `in`, which must outlive the reader; `name` stands for the file in messages.
  MappedLogReader(std::istream& in, std::string name, LogMap map, DriveLogLimits limits = {});
  MappedLogReader(const MappedLogReader&) = delete;  // holds its stream and pointers into its map
  MappedLogReader& operator=(const MappedLogReader&) = delete;

  /// The next row; false at the end of the file (after at least one row: a file without rows throws).
  bool next(MappedRow& row);

  [[nodiscard]] bool has(Quantity q) const noexcept { return index_[static_cast<std::size_t>(q)] >= 0; }
  [[nodiscard]] QuantitySet present() const noexcept;
  [[nodiscard]] const LogMap& map() const noexcept { return map_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  [[nodiscard]] std::uint64_t bytes_total() const noexcept { return bytes_total_; }
  [[nodiscard]] std::uint64_t bytes_read() const noexcept { return bytes_read_; }
  [[nodiscard]] const ReadRepairs& repairs() const noexcept { return repairs_; }

  /// The message's name of a quantity's column ("i_q"; "q_axis_current (i_q)" where a map renames it).
  [[nodiscard]] std::string label(Quantity q) const;
  /// Throws DriveLogError at `line` and the quantity's cell (its column; 0 for a header-level problem).
  [[noreturn]] void fail_at(std::size_t line, Quantity q, const std::string& reason) const;
  [[noreturn]] void fail_at(std::size_t line, const std::string& column, const std::string& reason) const;
  /// Refuses the header for what it lacks (a layout problem; "required …" reads "required column is missing from the
  /// header …"), adding what the header suggests: another separator where it is a single cell holding one, a column
  /// map (--log-map) where rpem's own format was assumed.
  [[noreturn]] void fail_header(const LayoutProblem& problem) const;

 private:
  void read_header();
  /// After the header: an optional column empty on every row is taken as absent (ReadRepairs::never_recorded), and
  /// so is a column with a no-reading value that holds nothing else (ReadRepairs::no_reading). Reads ahead only while
  /// some such column's cells have all been empty or no reading, then returns to the first row.
  void drop_columns_never_recorded();
  /// The repairs' entry of a column with a no-reading value, added at its first use.
  ReadRepairs::NoReading& no_reading_of(const std::string& label, const MappedColumn& c);
  void index_positions();  ///< a headerless map's cells: its columns' positions
  bool next_line(std::string& text);
  bool next_cells();  ///< the next row's cells, of the file's width; false at the end (or at a cut last row)
  bool read_raw(MappedRow& row);
  void check_session();  ///< the row belongs to the first row's recording (LogMap::session), else a DriveLogError
  void split(const std::string& line);
  [[nodiscard]] bool ends_with_separator(const std::string& line) const;  ///< blanks after it aside
  [[nodiscard]] bool cut_off() const;
  /// The cell's number as written (a cell that is not one is refused by line and cell); NaN only where allow_nan.
  [[nodiscard]] double number_in_cell(int index, const std::string& label, bool allow_nan);
  /// A cell's written number in SI through its column's map; NaN where it is NaN or the column's no-reading value.
  [[nodiscard]] double in_si(int index, const std::string& label, const MappedColumn& c, double written);
  [[nodiscard]] double cell(int index, const std::string& label, const MappedColumn& c, bool allow_nan) {
    return in_si(index, label, c, number_in_cell(index, label, allow_nan));
  }
  /// An empty cell: the error says how many rows from here leave the column empty (read to the file's end: the
  /// error ends the read anyway) — every one is a column the logger names and never recorded.
  [[noreturn]] void fail_empty_cell(int index, const std::string& label);
  void check(const MappedRow& row, int index, const std::string& label, Quantity q, double v) const;
  [[noreturn]] void fail_cell(int index, const std::string& label, const std::string& reason) const;

  std::string path_;
  std::ifstream file_;
  std::istream& in_;
  LogMap map_;
  DriveLogLimits limits_;
  std::size_t line_ = 0;
  std::uint64_t rows_ = 0;
  std::uint64_t bytes_total_ = 0;
  std::uint64_t bytes_read_ = 0;
  std::vector<std::string> header_;
  std::size_t header_line_ = 0;  ///< the file's line the header was read from
  std::size_t width_ = 0;        ///< cells per row (the header's, or a headerless file's first row's)
  bool trailing_separator_ = false;
  bool closed_ = false;  ///< the line just split ends with the separator its header ends with
  std::vector<std::string> cells_;
  std::array<int, kQuantityCount> index_{};  ///< 0-based cell of each quantity; −1 absent
  std::array<const MappedColumn*, kQuantityCount> column_{};
  int time_index_ = -1;
  std::string time_label_;
  int session_index_ = -1;        ///< the map's session column's cell; −1: none (or not in the header)
  std::string session_;           ///< the first row's session cell
  std::size_t session_line_ = 0;  ///< its line

  // Time: the previous raw (unwrapped, untied) stamp, the wraps so far, rows held to spread a tie.
  std::optional<std::int64_t> previous_raw_ns_;
  std::optional<double> previous_cell_s_;
  double wrap_offset_s_ = 0.0;
  std::optional<MappedRow> lookahead_;
  std::deque<MappedRow> ready_;
  std::uint64_t data_rows_ = 0;
  std::size_t first_data_line_ = 0;  ///< the file's line of the first data row
  ReadRepairs repairs_;
};

}  // namespace rpem::io
