#include "rpem/io/mapped_log.hpp"
#include "rpem/core/non_finite.hpp"
#include "rpem/io/number_text.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string_view>

namespace rpem::io {
namespace {

using core::kNaN;

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/// A number for a message (six significant digits).
std::string g6(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

MappedLogReader::MappedLogReader(const std::string& path, LogMap map, DriveLogLimits limits)
    : path_(path), file_(path, std::ios::binary), in_(file_), map_(std::move(map)), limits_(std::move(limits)) {
  if (!file_) throw DriveLogError(path, 0, 0, "", "cannot open file");
  std::error_code ec;
  bytes_total_ = std::filesystem::file_size(path, ec);
  read_header();
}

MappedLogReader::MappedLogReader(std::istream& in, std::string name, LogMap map, DriveLogLimits limits)
    : path_(std::move(name)), in_(in), map_(std::move(map)), limits_(std::move(limits)) {
  read_header();
}

void MappedLogReader::fail_at(std::size_t line, const std::string& column, const std::string& reason) const {
  throw DriveLogError(path_, line, 0, "column " + column, reason);
}

void MappedLogReader::fail_at(std::size_t line, Quantity q, const std::string& reason) const {
  const int index = index_[static_cast<std::size_t>(q)];
  throw DriveLogError(path_, line, index >= 0 ? static_cast<std::size_t>(index) + 1 : 0, "column " + label(q), reason);
}

void MappedLogReader::fail_header(const LayoutProblem& problem) const {
  // Named as the file would name it: the map's column for that quantity (VESC Tool's d_axis_voltage for u_d).
  const auto named = [&](Quantity q) {
    std::string quantity = info(q).name;
    for (const MappedColumn& c : map_.columns) {
      if (c.quantity == q && c.column.label() != quantity) return c.column.label() + " (" + quantity + ")";
    }
    return quantity;
  };
  constexpr std::string_view kRequired = "required";
  std::string reason = problem.reason.rfind(kRequired, 0) == 0
                           ? "required column is missing from the header" + problem.reason.substr(kRequired.size())
                           : problem.reason;
  reason += instead_text(problem, named);
  const std::string& only = header_.size() == 1 ? header_.front() : std::string();
  const std::size_t other = only.find_first_of(";,\t|");
  if (other != std::string::npos && only[other] != map_.separator) {
    const std::string shown = only[other] == '\t' ? std::string("a tab") : "'" + std::string(1, only[other]) + "'";
    reason += "; the header is one cell, \"" + only.substr(0, 60) + (only.size() > 60 ? "…" : "") +
              "\": are its cells separated by " + shown + "? rpem reads '" + std::string(1, map_.separator) +
              "' here; a column map's `separator:` reads another (--log-map; docs/drive-log.md, \"Column maps\")";
  } else if (map_.columns_optional) {
    reason +=
        "; a CSV of another layout is read through a column map: --log-map MAP.yaml (docs/drive-log.md, \"Column "
        "maps\")";
  }
  std::string column = problem.column;  // a quantity's name, or a group of them
  for (const MappedColumn& c : map_.columns) {
    if (problem.column == info(c.quantity).name) column = named(c.quantity);
  }
  fail_at(line_, column, reason);
}

void MappedLogReader::fail_cell(int index, const std::string& label, const std::string& reason) const {
  throw DriveLogError(path_, line_, static_cast<std::size_t>(index) + 1, "column " + label, reason);
}

std::string MappedLogReader::label(Quantity q) const {
  const MappedColumn* c = column_[static_cast<std::size_t>(q)];
  std::string name = info(q).name;  // not const: returned by move
  if (c == nullptr || c->column.name == name) return name;
  return c->column.label() + " (" + name + ")";
}

QuantitySet MappedLogReader::present() const noexcept {
  QuantitySet p{};
  for (std::size_t k = 0; k < kQuantityCount; ++k) p[k] = index_[k] >= 0;
  return p;
}

bool MappedLogReader::next_line(std::string& text) {
  while (std::getline(in_, text)) {
    ++line_;
    bytes_read_ += text.size() + 1;
    const auto first = std::find_if_not(text.begin(), text.end(), blank);
    if (first == text.end()) continue;                             // blank line
    if (map_.comment != '\0' && *first == map_.comment) continue;  // comment line
    return true;
  }
  return false;
}

void MappedLogReader::split(const std::string& line) {
  std::size_t n = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t sep = line.find(map_.separator, start);
    std::size_t first = start;
    std::size_t last = sep == std::string::npos ? line.size() : sep;
    while (first < last && blank(line[first])) ++first;
    while (last > first && blank(line[last - 1])) --last;
    if (last - first >= 2 && line[first] == '"' && line[last - 1] == '"') ++first, --last;  // a quoted cell
    if (n == cells_.size()) cells_.emplace_back();
    cells_[n++].assign(line, first, last - first);
    if (sep == std::string::npos) break;
    start = sep + 1;
  }
  cells_.resize(n);
  // VESC Tool ends every line with its separator: the empty cell after it is no column. Whether a row is so closed
  // is read from the row's own last character, never from its count: a row missing one value but closed has as
  // many cells as the header has names, and would be read with its values shifted into the wrong columns.
  closed_ = trailing_separator_ && ends_with_separator(line);
  if (closed_) cells_.pop_back();
}

bool MappedLogReader::ends_with_separator(const std::string& line) const {
  const auto last = std::find_if_not(line.rbegin(), line.rend(), [&](char c) { return blank(c) && c != map_.separator; });
  return last != line.rend() && *last == map_.separator;
}

// A logger writes a row at a time and ends it with a newline (VESC Tool flushes each row: vedderb/vesc_tool
// vescinterface.cpp, the valuesReceived handler), so a file copied while logging, or left by a logger killed or out
// of space, ends inside its last row: no newline after it, and cells or the closing separator missing. Only that
// line is taken for a cut row, and only after a whole one: a short row anywhere else is the error it always was.
bool MappedLogReader::cut_off() const {
  if (!in_.eof() || data_rows_ == 0) return false;  // the line ended with a newline, or no whole row came before
  return cells_.size() != width_ || (trailing_separator_ && !closed_);
}

// Positions are checked against the first row's width when it is read.
void MappedLogReader::index_positions() {
  for (const MappedColumn& c : map_.columns) {
    index_[static_cast<std::size_t>(c.quantity)] = static_cast<int>(c.column.position) - 1;
    column_[static_cast<std::size_t>(c.quantity)] = &c;
  }
  if (map_.time) time_index_ = static_cast<int>(map_.time->column.position) - 1;
  if (map_.time) time_label_ = map_.time->column.label() + " (t)";
  if (map_.session) session_index_ = static_cast<int>(map_.session->position) - 1;
}

void MappedLogReader::read_header() {
  index_.fill(-1);
  column_.fill(nullptr);
  for (std::size_t k = 0; k < map_.skip_lines; ++k) {
    std::string skipped;
    if (!std::getline(in_, skipped)) {
      throw DriveLogError(path_, line_, 0, "",
                          "the file ends after " + std::to_string(line_) + " lines, within the map's skip_lines (" +
                              std::to_string(map_.skip_lines) + ")");
    }
    ++line_;
    bytes_read_ += skipped.size() + 1;
  }
  if (!map_.header) {
    index_positions();
    return;
  }
  std::string header_line;
  if (!next_line(header_line))
    throw DriveLogError(path_, line_ == 0 ? 1 : line_, 0, "", "empty file: expected a header row");
  if (header_line.rfind("\xFF\xFE", 0) == 0 || header_line.rfind("\xFE\xFF", 0) == 0 ||
      header_line.find('\0') != std::string::npos)
    throw DriveLogError(path_, line_, 0, "",
                        "the file is UTF-16 text (a byte-order mark FF FE or FE FF, or a zero byte beside each "
                        "character: what Windows Notepad saves as \"Unicode\"); rpem reads UTF-8 or ASCII: save it as "
                        "UTF-8, e.g. iconv -f UTF-16 -t UTF-8 FILE > FIXED.csv");
  if (header_line.rfind("\xEF\xBB\xBF", 0) == 0) header_line.erase(0, 3);  // a UTF-8 byte-order mark
  if (std::all_of(header_line.begin(), header_line.end(), blank))
    throw DriveLogError(path_, line_, 0, "", "empty file: expected a header row (the file holds a byte-order mark alone)");
  if (const std::size_t cr = header_line.find('\r');
      cr != std::string::npos &&
      !std::all_of(header_line.begin() + static_cast<std::ptrdiff_t>(cr), header_line.end(), blank))
    throw DriveLogError(path_, line_, 0, "",
                        "its lines end in a carriage return alone (classic Mac OS line endings), so the whole file reads "
                        "as one line; rpem reads lines ending in a newline or CR LF: convert it, e.g. tr '\\r' '\\n' < "
                        "FILE > FIXED.csv");
  trailing_separator_ = ends_with_separator(header_line);
  split(header_line);  // closed by its separator if it ends with one: that empty cell is no column's name
  header_ = cells_;
  header_line_ = line_;
  width_ = header_.size();

  auto find = [&](const std::string& name, const std::string& label) {
    int index = -1;
    for (std::size_t k = 0; k < header_.size(); ++k) {
      if (header_[k] != name) continue;
      if (index >= 0) fail_at(line_, label, "column appears twice in the header");
      index = static_cast<int>(k);
    }
    return index;
  };
  auto missing = [&](const std::string& label) {
    fail_header(
        {label, map_.columns_optional ? "required" : "is missing from the header (the map " + map_.name + " reads it)"});
  };
  if (map_.session) session_index_ = find(map_.session->name, map_.session->name);  // where the file has it
  if (map_.time) {
    time_label_ = map_.time->column.name == "t" ? "t" : map_.time->column.name + " (t)";
    time_index_ = find(map_.time->column.name, time_label_);
    if (time_index_ < 0) missing(time_label_);
  }
  for (const MappedColumn& c : map_.columns) {
    const std::size_t q = static_cast<std::size_t>(c.quantity);
    column_[q] = &c;
    index_[q] = find(c.column.name, label(c.quantity));
    if (index_[q] < 0) {
      column_[q] = nullptr;
      if (!map_.columns_optional && !c.optional) {
        column_[q] = &c;
        missing(label(c.quantity));
      }
    }
  }
  drop_columns_never_recorded();
}

void MappedLogReader::drop_columns_never_recorded() {
  // Columns in the header without a value so far: optional ones, and those a logger may fill with its no-reading value.
  std::vector<const MappedColumn*> unseen;
  std::array<bool, kQuantityCount> saw_no_reading{};
  for (const MappedColumn& c : map_.columns) {
    if ((c.optional || c.no_reading) && index_[static_cast<std::size_t>(c.quantity)] >= 0) unseen.push_back(&c);
  }
  auto holds_a_value = [&](const MappedColumn& c, const std::string& text) {
    if (text.empty()) return false;
    const NumberText read = read_number(text);
    const bool no_reading = read.kind == NumberText::Kind::kNumber && is_no_reading(c, read.value);
    saw_no_reading[static_cast<std::size_t>(c.quantity)] |= no_reading;
    return !no_reading;  // anything else is a value, or an error its row's read reports
  };
  const std::istream::pos_type start = in_.tellg();
  if (unseen.empty() || start == std::istream::pos_type(-1)) return;  // nothing to look for, or a stream read once
  const std::size_t line = line_;
  const std::uint64_t bytes = bytes_read_;
  bool any_row = false;
  for (std::string text; !unseen.empty() && next_line(text);) {
    split(text);
    any_row = true;
    std::erase_if(unseen, [&](const MappedColumn* c) {
      const auto k = static_cast<std::size_t>(index_[static_cast<std::size_t>(c->quantity)]);
      return k < cells_.size() && holds_a_value(*c, cells_[k]);
    });
  }
  in_.clear();
  in_.seekg(start);
  line_ = line;
  bytes_read_ = bytes;
  if (!any_row) return;  // a file without rows: its own error, at the first read
  for (const MappedColumn* c : unseen) {
    const auto q = static_cast<std::size_t>(c->quantity);
    if (saw_no_reading[q]) {
      no_reading_of(label(c->quantity), *c).every_row = true;
    } else if (c->optional) {
      repairs_.never_recorded.push_back(label(c->quantity));
    } else {
      continue;  // a required column empty on every row: its first row's read says so
    }
    index_[q] = -1;
    column_[q] = nullptr;
  }
}

ReadRepairs::NoReading& MappedLogReader::no_reading_of(const std::string& label, const MappedColumn& c) {
  for (ReadRepairs::NoReading& r : repairs_.no_reading) {
    if (r.column == label) return r;
  }
  assert(c.no_reading);
  return repairs_.no_reading.emplace_back(ReadRepairs::NoReading{label, g6(*c.no_reading) + " " + c.unit});
}

void MappedLogReader::fail_empty_cell(int index, const std::string& label) {
  const std::size_t at = line_, column = static_cast<std::size_t>(index);
  const bool first_row = line_ == first_data_line_;
  std::uint64_t rows = 1, empty = 1;
  std::size_t recorded_at = 0;  // the first line after this one that has the cell
  for (std::string text; next_line(text);) {
    split(text);
    if (cells_.size() <= column) continue;  // a short row is its own error, at its turn
    ++rows;
    if (cells_[column].empty()) {
      ++empty;
    } else if (recorded_at == 0) {
      recorded_at = line_;
    }
  }
  line_ = at;  // the error names the row where the read stopped
  std::string reason = "empty cell";
  if (empty == rows) {
    reason += first_row ? ", and so on every row (" + std::to_string(rows) +
                              "): the logger names the column in its header but recorded no value in it — a logger "
                              "or firmware that does not report this quantity; rpem cannot read the log without it"
                        : ", and so on every row from here to the end (" + std::to_string(rows) +
                              "): the logger stopped recording it; cut the rows from here off to read the rest";
  } else {
    reason += " (" + std::to_string(empty) + " of the " + std::to_string(rows) + " rows from here leave it empty; line " +
              std::to_string(recorded_at) + " is the first after it that has it" +
              (first_row ? ": the logger filled it in after its first rows — delete the rows before it)" : ")");
  }
  fail_cell(index, label, reason);
}

double MappedLogReader::number_in_cell(int index, const std::string& label, bool allow_nan) {
  const std::string& s = cells_[static_cast<std::size_t>(index)];
  if (s.empty()) fail_empty_cell(index, label);
  const NumberText read = read_number(s);
  const double v = read.value;
  if (read.kind != NumberText::Kind::kNumber) {
    // A spreadsheet saving the file in a locale with a decimal comma writes "24,9" (and ';' between cells).
    std::string with_point = s;
    std::replace(with_point.begin(), with_point.end(), ',', '.');
    const bool decimal_comma = std::count(s.begin(), s.end(), ',') == 1 && is_number_text(with_point);
    fail_cell(index, label,
              read.reason(s) + (decimal_comma
                                    ? " (a decimal comma: saved by a spreadsheet in a locale that writes them? rpem reads "
                                      "a decimal point, as VESC Tool and most loggers write it)"
                                    : ""));
  }
  if (std::isnan(v)) {
    if (allow_nan) return kNaN;
    fail_cell(index, label, "NaN");
  }
  if (!std::isfinite(v)) fail_cell(index, label, "'" + s + "' is not finite");
  return v;
}

double MappedLogReader::in_si(int index, const std::string& label, const MappedColumn& c, double written) {
  if (std::isnan(written)) return kNaN;
  if (is_no_reading(c, written)) {
    ++no_reading_of(label, c).rows;
    return kNaN;
  }
  const double si = c.unit_factor * (written * c.scale + c.offset) + c.unit_offset;
  if (!std::isfinite(si)) {
    fail_cell(index, label, "'" + cells_[static_cast<std::size_t>(index)] + "' is not finite in SI (" + c.unit + ")");
  }
  return si;
}

void MappedLogReader::check(const MappedRow& row, int index, const std::string& label, Quantity q, double v) const {
  const QuantityInfo& i = info(q);
  const char* unit = "";
  const Bound* bound = nullptr;
  switch (i.kind) {
    case QuantityKind::kTime:
      bound = &limits_.time_s, unit = "s";
      break;
    case QuantityKind::kAngle:
      bound = &limits_.angle_rad, unit = "rad";
      break;
    case QuantityKind::kSpeed:
      bound = &limits_.speed_rad_s, unit = "rad/s";
      break;
    case QuantityKind::kVoltage:  // the DC link is the inverter's: its own bound, never narrowed to a machine
      bound = q == Quantity::kUDc ? &limits_.dc_link_V : &limits_.voltage_V, unit = "V";
      break;
    case QuantityKind::kCurrent:
      bound = &limits_.current_A, unit = "A";
      break;
    case QuantityKind::kTorque:
      bound = &limits_.torque_Nm, unit = "Nm";
      break;
    case QuantityKind::kRatio:
      bound = &limits_.duty, unit = "x u_dc/√3";
      break;
    case QuantityKind::kTemperature:
      if (v < limits_.temperature_min_C || v > limits_.temperature_max_C) {
        fail_cell(index, label,
                  g6(v) + " °C is outside the plausible [" + g6(limits_.temperature_min_C) + ", " +
                      g6(limits_.temperature_max_C) + "] °C");
      }
      return;
  }
  if (std::abs(v) > bound->max_abs) {
    fail_cell(index, label,
              g6(v) + " " + unit + " is beyond the plausible ±" + g6(bound->max_abs) + " " + unit + " (" + bound->why + ")");
  }
  const double u_dc = row[Quantity::kUDc];
  if (i.voltage_command && u_dc >= 1.0 && std::abs(v) > limits_.command_per_dc_link * u_dc) {
    fail_cell(index, label,
              g6(v) + " V is more than " + g6(limits_.command_per_dc_link) + " x this row's u_dc = " + g6(u_dc) +
                  " V (a two-level inverter applies at most u_dc/2 from the link's midpoint)");
  }
}

bool MappedLogReader::next_cells() {
  std::string text;
  if (!next_line(text)) return false;
  split(text);
  if (cut_off()) {
    repairs_.cut_line = line_;
    return false;
  }
  if (map_.header && cells_ == header_) {
    fail_at(line_, "*",
            "the header again (as on line " + std::to_string(header_line_) +
                "): two logs joined into one file? Read each log on its own");
  }
  if (!map_.header && width_ == 0) {
    width_ = cells_.size();
    for (std::size_t q = 0; q < kQuantityCount; ++q) {
      if (index_[q] >= static_cast<int>(width_)) {
        fail_at(
            line_, static_cast<Quantity>(q),
            "the map reads cell " + std::to_string(index_[q] + 1) + ", the row has " + std::to_string(width_) + " cells");
      }
    }
    if (time_index_ >= static_cast<int>(width_)) {
      fail_at(
          line_, time_label_,
          "the map reads cell " + std::to_string(time_index_ + 1) + ", the row has " + std::to_string(width_) + " cells");
    }
  }
  if (cells_.size() != width_) {
    fail_at(line_, "*",
            "row has " + std::to_string(cells_.size()) + " cells, " + (map_.header ? "header has " : "the first row has ") +
                std::to_string(width_));
  }
  if (session_index_ >= 0) check_session();
  return true;
}

void MappedLogReader::check_session() {
  if (session_index_ >= static_cast<int>(width_)) {
    fail_at(line_, map_.session->label(),
            "the map's session column is cell " + std::to_string(session_index_ + 1) + ", the row has " +
                std::to_string(width_) + " cells");
  }
  const std::string& here = cells_[static_cast<std::size_t>(session_index_)];
  if (session_line_ == 0) {
    session_ = here;
    session_line_ = line_;
    return;
  }
  if (here == session_) return;
  // A different spelling of one number ("4", "4.0") is the same recording.
  const NumberText a = read_number(here), b = read_number(session_);
  if (a.kind == NumberText::Kind::kNumber && b.kind == NumberText::Kind::kNumber && a.value == b.value) return;
  fail_cell(session_index_, map_.session->label(),
            "a second recording begins here ('" + here + "'; the rows from line " + std::to_string(session_line_) +
                " are '" + session_ +
                "'): each starts from its own state and the time between them is not in the "
                "file. Read one recording at a time: cut its rows into a file of their own");
}

bool MappedLogReader::read_raw(MappedRow& row) {
  if (!next_cells()) return false;
  if (data_rows_ == 0) first_data_line_ = line_;
  row.line = line_;
  row.value.fill(kNaN);

  // Time: the column's value (unwrapped), or the row's index times the period.
  std::int64_t t_ns = 0;
  if (map_.time) {
    const MappedColumn& c = *map_.time;
    const double written = number_in_cell(time_index_, time_label_, false);
    double t_s = in_si(time_index_, time_label_, c, written);
    if (std::abs(t_s) > limits_.time_s.max_abs) {
      fail_cell(time_index_, time_label_,
                g6(t_s) + " s is beyond the plausible ±" + g6(limits_.time_s.max_abs) + " s (" + limits_.time_s.why + ")");
    }
    if (map_.wrap_s > 0.0) {
      // A wrapping clock's value lies within one period of its zero (ms_today: 0 to a day): what lies outside is
      // not that clock, and would unwrap to a window years long or a wrap that never happened.
      const double zero_s = c.unit_factor * c.offset + c.unit_offset;  // the column's 0 in seconds
      if (!(t_s >= zero_s && t_s < zero_s + map_.wrap_s)) {
        fail_cell(time_index_, time_label_,
                  g6(t_s - zero_s) + " s is outside the column's period [0, " + g6(map_.wrap_s) + ") s (it wraps every " +
                      g6(map_.wrap_s) + " s)");
      }
    }
    if (map_.resolution_s > 0.0) {
      // A stamp is a whole number of its clock's steps: a value between two is a clock in another unit than the map
      // says (seconds under `unit: ms` with `resolution: 1`). The tolerance is the double's own, at the value's size.
      const double ticks = written * c.unit_factor * c.scale / map_.resolution_s;
      if (std::abs(ticks - std::round(ticks)) > 1e-9 * std::abs(ticks) + 1e-6) {
        fail_cell(time_index_, time_label_,
                  "'" + cells_[static_cast<std::size_t>(time_index_)] + "' lies between two steps of the column's " +
                      "resolution (" + g6(map_.resolution_s / (c.unit_factor * c.scale)) + " " + c.unit +
                      ", the map's time.resolution): is the column in another unit than the map's `unit: " + c.unit +
                      "` (seconds read as ms)?");
      }
    }
    if (previous_cell_s_ && map_.wrap_s > 0.0 && t_s < *previous_cell_s_ - 0.5 * map_.wrap_s) {
      // A step back by more than half the period is the column wrapping (ms_today at midnight): the
      // shorter way round the clock is forward. A shorter step back is time going back.
      wrap_offset_s_ += map_.wrap_s;
      ++repairs_.wraps;
    }
    previous_cell_s_ = t_s;
    t_ns = std::llround((t_s + wrap_offset_s_) * 1e9);
  } else {
    t_ns = std::llround(static_cast<double>(data_rows_) * map_.period_s * 1e9);
  }
  ++data_rows_;
  if (previous_raw_ns_ && t_ns <= *previous_raw_ns_) {
    if (!(t_ns == *previous_raw_ns_ && map_.resolution_s > 0.0)) {
      std::string reason = "time does not increase (by at least 1 ns)";
      if (map_.wrap_s > 0.0 && t_ns < *previous_raw_ns_) {
        reason = "time goes back by " + g6(1e-9 * static_cast<double>(*previous_raw_ns_ - t_ns)) +
                 " s (the column wraps every " + g6(map_.wrap_s) + " s; a wrap steps back by more than half of that)";
      }
      fail_cell(time_index_, time_label_, reason);
    }
  }
  previous_raw_ns_ = t_ns;
  row.t_ns = t_ns;

  for (std::size_t q = 0; q < kQuantityCount; ++q) {
    if (index_[q] < 0) continue;
    const MappedColumn& c = *column_[q];
    const bool allow_nan = (map_.nan_u_dc_is_missing && c.quantity == Quantity::kUDc) ||
                           (map_.nan_temperature_is_no_reading && info(c.quantity).kind == QuantityKind::kTemperature);
    row.value[q] = cell(index_[q], label(c.quantity), c, allow_nan);
  }
  // Checked after every cell is read: a command is held to its row's u_dc.
  for (std::size_t q = 0; q < kQuantityCount; ++q) {
    if (index_[q] >= 0 && !std::isnan(row.value[q]))
      check(row, index_[q], label(static_cast<Quantity>(q)), static_cast<Quantity>(q), row.value[q]);
  }
  return true;
}

bool MappedLogReader::next(MappedRow& row) {
  if (ready_.empty()) {
    MappedRow first;
    if (lookahead_) {
      first = *lookahead_;
      lookahead_.reset();
    } else if (!read_raw(first)) {
      if (rows_ == 0) throw DriveLogError(path_, line_, 0, "", "no samples: the header is followed by no data rows");
      return false;
    }
    ready_.push_back(first);
    if (map_.resolution_s > 0.0) {
      // Rows stamped alike (VESC Tool handled several replies within its clock's millisecond) are spread
      // evenly over the stamp's resolution: each stays inside the interval its stamp stands for.
      MappedRow r;
      while (read_raw(r)) {
        if (r.t_ns != first.t_ns) {
          lookahead_ = r;
          break;
        }
        ready_.push_back(r);
      }
      const double n = static_cast<double>(ready_.size());
      for (std::size_t j = 1; j < ready_.size(); ++j) {
        ready_[j].t_ns += std::llround(static_cast<double>(j) / n * map_.resolution_s * 1e9);
        ++repairs_.tied_rows;
      }
      if (lookahead_ && ready_.back().t_ns >= lookahead_->t_ns) {
        fail_at(lookahead_->line, time_label_,
                "stamped within the resolution (" + g6(map_.resolution_s) +
                    " s) of a run of equal stamps before it: the column is finer than the "
                    "map's time.resolution");
      }
    }
  }
  row = ready_.front();
  ready_.pop_front();
  ++rows_;
  return true;
}

}  // namespace rpem::io
