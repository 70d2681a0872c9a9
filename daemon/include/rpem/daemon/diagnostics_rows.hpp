#pragma once
// How a thread's counters and statistics reach RPEM_DIAGNOSTICS. Each value has one writer, the thread
// that counts it; that thread sends a DiagnosticsRows through its queue to the publisher, which writes
// the rows into diagnostics_t knowing nothing of what they mean. A thread lists its counters in a
// table of CounterRow — where it counts, which diagnostics_t field — so adding a counter is its line in
// lcm_types/rpem_diagnostics_t.lcm (the one definition of the message: lcm-gen's class, the field list
// that `rpem listen --diagnostics` prints from; docs/architecture.md, "One definition per message") and
// one row here. Plain data, fixed size: real-time safe.

#include <array>
#include <cstddef>
#include <cstdint>

#include "rpem/core/assert.hpp"
#include "rpem/diagnostics_t.hpp"

namespace rpem::daemon {

using DiagnosticsCount = std::int64_t rpem::diagnostics_t::*;
using DiagnosticsFigure = double rpem::diagnostics_t::*;

/// One row of a thread's counter table: the member of its counters struct → the diagnostics_t field.
template <class Counters, class T = std::int64_t>
struct CounterRow {
  T Counters::*count;
  DiagnosticsCount field;
};

class DiagnosticsRows {
 public:
  static constexpr std::size_t kMaxCounts = 32;
  static constexpr std::size_t kMaxFigures = 16;

  /// Sets a field (replacing an earlier row for it). Rows beyond the capacity are dropped (an assertion
  /// where assertions are on); the tables are checked against it at compile time where they are defined.
  void set(DiagnosticsCount field, std::int64_t value) noexcept { put(counts_, n_counts_, field, value); }
  void set(DiagnosticsFigure field, double value) noexcept { put(figures_, n_figures_, field, value); }

  /// Every row of `table` (CounterRows), read from `counters`.
  template <class Table, class Counters>
  void set_all(const Table& table, const Counters& counters) noexcept {
    for (const auto& row : table) set(row.field, static_cast<std::int64_t>(counters.*row.count));
  }

  /// Writes every row into `m`.
  void write_to(rpem::diagnostics_t& m) const noexcept {
    for (std::size_t k = 0; k < n_counts_; ++k) m.*counts_[k].field = counts_[k].value;
    for (std::size_t k = 0; k < n_figures_; ++k) m.*figures_[k].field = figures_[k].value;
  }

  /// The value of a field's row, or `absent` (for tests and the status line).
  [[nodiscard]] std::int64_t get(DiagnosticsCount field, std::int64_t absent = -1) const noexcept {
    return find(counts_, n_counts_, field, absent);
  }
  [[nodiscard]] double get(DiagnosticsFigure field, double absent = -1.0) const noexcept {
    return find(figures_, n_figures_, field, absent);
  }

 private:
  template <class Field, class T>
  struct Row {
    Field field = nullptr;
    T value{};
  };
  template <class Field, class T, std::size_t N>
  static void put(std::array<Row<Field, T>, N>& rows, std::size_t& n, Field field, T value) noexcept {
    for (std::size_t k = 0; k < n; ++k) {
      if (rows[k].field == field) {
        rows[k].value = value;
        return;
      }
    }
    RPEM_ASSERT(n < N, "a thread's rows fit DiagnosticsRows (kMaxCounts, kMaxFigures)");
    if (n < N) rows[n++] = {field, value};
  }
  template <class Field, class T, std::size_t N>
  static T find(const std::array<Row<Field, T>, N>& rows, std::size_t n, Field field, T absent) noexcept {
    for (std::size_t k = 0; k < n; ++k) {
      if (rows[k].field == field) return rows[k].value;
    }
    return absent;
  }

  std::array<Row<DiagnosticsCount, std::int64_t>, kMaxCounts> counts_{};
  std::array<Row<DiagnosticsFigure, double>, kMaxFigures> figures_{};
  std::size_t n_counts_ = 0;
  std::size_t n_figures_ = 0;
};

}  // namespace rpem::daemon
