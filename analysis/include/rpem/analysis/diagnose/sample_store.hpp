#pragma once
// A drive log's samples kept once, compactly, for `rpem diagnose` (docs/diagnose.md, "Long recordings"). A
// sample is ten numbers — t, θ, ω, u_dc, three voltages, three currents — and the temperatures the log has;
// they are stored by column, in chunks of kChunk samples, and each chunk of a column as float where every
// value of it is a float exactly (a temperature logged in whole degrees, a VESC current in steps of 1/16 A),
// else as double: nothing a replay computes from a sample changes with the storage. Times are integer
// nanoseconds, as 32-bit offsets from the chunk's first where the chunk spans less than 4.29 s. One byte per
// sample marks it: a gap before it, left out of the replay, a regime (core::Regime's number: room for a
// per-sample classification, 3 bits), and whether each temperature column has a reading on it. A temperature
// column is stored as its newest reading held (a slow sensor reads on few rows: docs/drive-log.md), so that the
// temperature at every row costs nothing more. What a sample is not stored with: torque_cmd and the receive stamp
// (rx_ns), which no diagnosis reads; the frames, which a log keeps throughout.
//
// Appending (push_back, then finish) needs a chunk of staging space, not the log's; reading decodes one
// sample at a time.

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "rpem/core/drive_sample.hpp"
#include "rpem/io/drive_log.hpp"

namespace rpem::analysis {

/// What one byte per sample says about it (SampleStore::mark).
namespace sample_mark {
inline constexpr std::uint8_t kGapBefore = 1U << 0;  ///< samples were lost before it (DriveSample::gap_before)
inline constexpr std::uint8_t kLeftOut = 1U << 1;    ///< takes no part in the replay (LogData::used)
inline constexpr unsigned kRegimeShift = 2;          ///< core::Regime's number in bits 2–4
inline constexpr std::uint8_t kRegimeMask = 0x7U << kRegimeShift;
inline constexpr std::uint8_t kWindingReading = 1U << 5;  ///< the winding temperature column has a reading on it
inline constexpr std::uint8_t kMagnetReading = 1U << 6;   ///< the magnet temperature column has a reading on it
}  // namespace sample_mark

class SampleStore {
 public:
  /// Samples per chunk (a power of two: k/kChunk and k%kChunk are a shift and a mask).
  static constexpr std::size_t kChunkBits = 14;
  static constexpr std::size_t kChunk = std::size_t{1} << kChunkBits;

  SampleStore() = default;
  /// Empty, for samples of a log with `layout`'s temperature columns.
  explicit SampleStore(const io::DriveLogLayout& layout);

  /// Appends a row; its frames must be those of the first (a log keeps its frames) and its time not before
  /// the previous (throws std::invalid_argument otherwise: rows built in memory). Not after finish().
  void push_back(const io::DriveLogRow& row);
  /// The next row opens another session (a folder's next log): no reading is held over into it.
  void start_session() noexcept;
  /// Stores the last, partial chunk; the store is then complete and read-only.
  void finish();

  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }

  /// Sample k as logged (rx_ns 0).
  [[nodiscard]] core::DriveSample sample(std::size_t k) const noexcept;
  [[nodiscard]] std::int64_t t_ns(std::size_t k) const noexcept;
  [[nodiscard]] double theta_el_rad(std::size_t k) const noexcept { return value(kTheta, k); }
  [[nodiscard]] double omega_el_rad_s(std::size_t k) const noexcept { return value(kOmega, k); }
  [[nodiscard]] double u_dc_V(std::size_t k) const noexcept { return value(kUDc, k); }
  /// The temperatures read on row k: none where the log has no such column or no reading on the row (its
  /// logger's value for none, io::MappedColumn::no_reading; a slow sensor between its readings).
  [[nodiscard]] std::optional<double> t_winding_C(std::size_t k) const noexcept;
  [[nodiscard]] std::optional<double> t_magnet_C(std::size_t k) const noexcept;
  /// The temperatures at row k, as the diagnosis's models take them: the newest reading of the row's session
  /// at or before it, else (rows before the session's first reading) that first reading; none where the
  /// column or the session has no reading. Off the true temperature by at most |dT/dt| times the interval
  /// between readings (docs/diagnose.md, "Temperatures between readings").
  [[nodiscard]] std::optional<double> t_winding_held_C(std::size_t k) const noexcept;
  [[nodiscard]] std::optional<double> t_magnet_held_C(std::size_t k) const noexcept;
  [[nodiscard]] bool has_t_winding() const noexcept { return has_winding_; }
  [[nodiscard]] bool has_t_magnet() const noexcept { return has_magnet_; }

  [[nodiscard]] std::uint8_t mark(std::size_t k) const noexcept { return chunk(k).marks[k & (kChunk - 1)]; }
  [[nodiscard]] bool gap_before(std::size_t k) const noexcept { return (mark(k) & sample_mark::kGapBefore) != 0; }
  /// Sets or clears bits of sample k's mark.
  void set_mark(std::size_t k, std::uint8_t bits, bool on) noexcept {
    std::uint8_t& m = chunks_[k >> kChunkBits].marks[k & (kChunk - 1)];
    m = static_cast<std::uint8_t>(on ? m | bits : m & ~bits);
  }

  /// Heap bytes the store holds (capacity), for reports and tests.
  [[nodiscard]] std::size_t bytes() const noexcept;
  /// Chunks stored as float, of all chunks of the value columns (reports).
  [[nodiscard]] std::pair<std::size_t, std::size_t> float_chunks() const noexcept;

 private:
  enum Column : std::size_t { kTheta, kOmega, kUDc, kU0, kU1, kU2, kI0, kI1, kI2, kWinding, kMagnet, kColumns };

  /// A temperature column's newest reading, held while rows come (push); and, per session whose first rows
  /// came before its first reading, those rows and that reading (lead_of), which the held value cannot give.
  class HeldReading {
   public:
    /// Row k's reading (NaN: none) → the value to store: the reading, else the session's newest (NaN: none yet).
    double push(double reading, std::size_t k);
    void start_session() noexcept {
      newest_ = kNoReading;
      lead_first_.reset();
    }
    /// The first reading of row k's session where k came before it; none otherwise.
    [[nodiscard]] std::optional<double> lead_of(std::size_t k) const noexcept;
    [[nodiscard]] std::size_t bytes() const noexcept { return leads_.capacity() * sizeof(Lead); }

   private:
    static constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();
    struct Lead {
      std::size_t first = 0, end = 0;  ///< rows [first, end) take `value`, their session's first reading
      double value = 0.0;
    };
    double newest_ = kNoReading;
    std::optional<std::size_t> lead_first_;  ///< the session's rows without a reading so far start here
    std::vector<Lead> leads_;
  };

  /// One column's values of one chunk: float where all of them are floats exactly, else double.
  struct Values {
    std::vector<float> single;
    std::vector<double> full;
    [[nodiscard]] double at(std::size_t j) const noexcept { return full.empty() ? static_cast<double>(single[j]) : full[j]; }
  };
  struct Chunk {
    std::int64_t t0_ns = 0;
    std::vector<std::uint32_t> dt_ns;  ///< t − t0 where the chunk spans less than 2³² ns …
    std::vector<std::int64_t> t_ns;    ///< … else the times themselves
    std::array<Values, kColumns> columns;
    std::vector<std::uint8_t> marks;
  };

  [[nodiscard]] const Chunk& chunk(std::size_t k) const noexcept { return chunks_[k >> kChunkBits]; }
  [[nodiscard]] double value(Column c, std::size_t k) const noexcept { return chunk(k).columns[c].at(k & (kChunk - 1)); }
  void store_chunk();

  [[nodiscard]] std::optional<double> reading(Column c, std::uint8_t bit, std::size_t k) const noexcept;
  [[nodiscard]] std::optional<double> held(Column c, const HeldReading& h, std::size_t k) const noexcept;

  bool has_winding_ = false, has_magnet_ = false;
  HeldReading winding_, magnet_;
  core::Frame voltage_frame_ = core::Frame::kAbc, current_frame_ = core::Frame::kAbc;
  std::size_t size_ = 0;
  bool finished_ = false;
  std::vector<Chunk> chunks_;
  /// The chunk being filled, as doubles (staging; released by finish()).
  std::vector<std::int64_t> staged_t_;
  std::array<std::vector<double>, kColumns> staged_;
  std::vector<std::uint8_t> staged_marks_;
};

}  // namespace rpem::analysis
