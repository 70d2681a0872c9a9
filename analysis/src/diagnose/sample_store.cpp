#include "rpem/analysis/diagnose/sample_store.hpp"
#include "rpem/core/non_finite.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

namespace rpem::analysis {
namespace {

/// Whether x survives the round trip through float (NaN does: a missing reading stays missing).
bool single_exact(double x) noexcept { return std::isnan(x) || static_cast<double>(static_cast<float>(x)) == x; }

using core::kNaN;

}  // namespace

SampleStore::SampleStore(const io::DriveLogLayout& layout) : has_winding_(layout.t_winding), has_magnet_(layout.t_magnet) {}

void SampleStore::push_back(const io::DriveLogRow& row) {
  if (finished_) throw std::logic_error("SampleStore::push_back after finish()");
  const core::DriveSample& s = row.sample;
  if (size_ == 0) {
    voltage_frame_ = s.voltage_frame;
    current_frame_ = s.current_frame;
  } else if (s.voltage_frame != voltage_frame_ || s.current_frame != current_frame_) {
    throw std::invalid_argument("a log's rows change frames at row " + std::to_string(size_ + 1));
  } else if (s.t_ns < (staged_t_.empty() ? t_ns(size_ - 1) : staged_t_.back())) {
    throw std::invalid_argument("a log's time goes back at row " + std::to_string(size_ + 1));
  }
  if (staged_t_.empty()) {
    staged_t_.reserve(kChunk);
    staged_marks_.reserve(kChunk);
    for (auto& c : staged_) c.reserve(kChunk);
  }
  const double winding = has_winding_ ? row.sample.t_winding_C : kNaN;
  const double magnet = has_magnet_ ? row.t_magnet_C.value_or(kNaN) : kNaN;
  staged_t_.push_back(s.t_ns);
  staged_marks_.push_back(static_cast<std::uint8_t>((s.gap_before ? sample_mark::kGapBefore : 0) |
                                                    (std::isnan(winding) ? 0 : sample_mark::kWindingReading) |
                                                    (std::isnan(magnet) ? 0 : sample_mark::kMagnetReading)));
  const double values[kColumns] = {s.theta_el_rad,
                                   s.omega_el_rad_s,
                                   s.u_dc_V,
                                   s.u_V[0],
                                   s.u_V[1],
                                   s.u_V[2],
                                   s.i_A[0],
                                   s.i_A[1],
                                   s.i_A[2],
                                   has_winding_ ? winding_.push(winding, size_) : 0.0,
                                   has_magnet_ ? magnet_.push(magnet, size_) : 0.0};
  for (std::size_t c = 0; c < kColumns; ++c) staged_[c].push_back(values[c]);
  ++size_;
  if (staged_t_.size() == kChunk) store_chunk();
}

void SampleStore::start_session() noexcept {
  winding_.start_session();
  magnet_.start_session();
}

double SampleStore::HeldReading::push(double reading, std::size_t k) {
  if (std::isnan(reading)) {
    if (std::isnan(newest_) && !lead_first_) lead_first_ = k;
    return newest_;
  }
  if (lead_first_) leads_.push_back({*lead_first_, k, reading});
  lead_first_.reset();
  newest_ = reading;
  return reading;
}

std::optional<double> SampleStore::HeldReading::lead_of(std::size_t k) const noexcept {
  const auto after =
      std::upper_bound(leads_.begin(), leads_.end(), k, [](std::size_t r, const Lead& l) { return r < l.first; });
  if (after == leads_.begin()) return std::nullopt;
  const Lead& l = *std::prev(after);
  return k < l.end ? std::optional(l.value) : std::nullopt;
}

void SampleStore::store_chunk() {
  Chunk chunk;
  const std::size_t m = staged_t_.size();
  chunk.t0_ns = staged_t_.front();
  if (staged_t_.back() - chunk.t0_ns <= static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max())) {
    chunk.dt_ns.resize(m);
    for (std::size_t j = 0; j < m; ++j) chunk.dt_ns[j] = static_cast<std::uint32_t>(staged_t_[j] - chunk.t0_ns);
  } else {
    chunk.t_ns = staged_t_;
  }
  for (std::size_t c = 0; c < kColumns; ++c) {
    const bool stored = c < kWinding || (c == kWinding ? has_winding_ : has_magnet_);
    if (!stored) continue;
    const std::vector<double>& v = staged_[c];
    bool single = true;
    for (double x : v) single = single && single_exact(x);
    if (single) {
      chunk.columns[c].single.assign(v.begin(), v.end());  // each one exact (checked)
    } else {
      chunk.columns[c].full = v;
    }
    staged_[c].clear();
  }
  chunk.marks = staged_marks_;
  staged_t_.clear();
  staged_marks_.clear();
  chunks_.push_back(std::move(chunk));
}

void SampleStore::finish() {
  if (finished_) return;
  if (!staged_t_.empty()) store_chunk();
  finished_ = true;
  // Released, not only cleared (`v = {}` would assign an empty list and keep the capacity).
  staged_t_ = std::vector<std::int64_t>();
  staged_marks_ = std::vector<std::uint8_t>();
  for (auto& c : staged_) c = std::vector<double>();
}

core::DriveSample SampleStore::sample(std::size_t k) const noexcept {
  assert(finished_ && k < size_);
  const Chunk& c = chunk(k);
  const std::size_t j = k & (kChunk - 1);
  core::DriveSample s;
  s.t_ns = c.dt_ns.empty() ? c.t_ns[j] : c.t0_ns + c.dt_ns[j];
  s.theta_el_rad = c.columns[kTheta].at(j);
  s.omega_el_rad_s = c.columns[kOmega].at(j);
  s.u_dc_V = c.columns[kUDc].at(j);
  s.voltage_frame = voltage_frame_;
  s.u_V = {c.columns[kU0].at(j), c.columns[kU1].at(j), c.columns[kU2].at(j)};
  s.current_frame = current_frame_;
  s.i_A = {c.columns[kI0].at(j), c.columns[kI1].at(j), c.columns[kI2].at(j)};
  s.gap_before = (c.marks[j] & sample_mark::kGapBefore) != 0;
  return s;
}

std::int64_t SampleStore::t_ns(std::size_t k) const noexcept {
  const Chunk& c = chunk(k);
  const std::size_t j = k & (kChunk - 1);
  return c.dt_ns.empty() ? c.t_ns[j] : c.t0_ns + c.dt_ns[j];
}

std::optional<double> SampleStore::reading(Column c, std::uint8_t bit, std::size_t k) const noexcept {
  return (mark(k) & bit) != 0 ? std::optional(value(c, k)) : std::nullopt;
}

// The stored value is the session's newest reading (NaN: none yet in the session).
std::optional<double> SampleStore::held(Column c, const HeldReading& h, std::size_t k) const noexcept {
  const double v = value(c, k);
  return std::isnan(v) ? h.lead_of(k) : std::optional(v);
}

std::optional<double> SampleStore::t_winding_C(std::size_t k) const noexcept {
  return reading(kWinding, sample_mark::kWindingReading, k);
}
std::optional<double> SampleStore::t_magnet_C(std::size_t k) const noexcept {
  return reading(kMagnet, sample_mark::kMagnetReading, k);
}
std::optional<double> SampleStore::t_winding_held_C(std::size_t k) const noexcept {
  return has_winding_ ? held(kWinding, winding_, k) : std::nullopt;
}
std::optional<double> SampleStore::t_magnet_held_C(std::size_t k) const noexcept {
  return has_magnet_ ? held(kMagnet, magnet_, k) : std::nullopt;
}

std::size_t SampleStore::bytes() const noexcept {
  std::size_t b = chunks_.capacity() * sizeof(Chunk);
  for (const Chunk& c : chunks_) {
    b += c.dt_ns.capacity() * sizeof(std::uint32_t) + c.t_ns.capacity() * sizeof(std::int64_t) + c.marks.capacity();
    for (const Values& v : c.columns) b += v.single.capacity() * sizeof(float) + v.full.capacity() * sizeof(double);
  }
  b += staged_t_.capacity() * sizeof(std::int64_t) + staged_marks_.capacity() + winding_.bytes() + magnet_.bytes();
  for (const auto& v : staged_) b += v.capacity() * sizeof(double);
  return b;
}

std::pair<std::size_t, std::size_t> SampleStore::float_chunks() const noexcept {
  std::size_t single = 0, all = 0;
  for (const Chunk& c : chunks_) {
    for (const Values& v : c.columns) {
      if (v.single.empty() && v.full.empty()) continue;
      ++all;
      single += v.full.empty() ? 1 : 0;
    }
  }
  return {single, all};
}

}  // namespace rpem::analysis
