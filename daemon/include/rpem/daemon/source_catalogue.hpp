#pragma once
// The sample sources rpemd knows. `daemon.source.type` names one; `daemon.source.<type>` holds its
// options (sections of the other types may be present and are checked too). A new source is one
// implementation — a struct with kType, Options, parse(), sample_kind() and make() (and sample_spacing() where
// the source, not the drive, sets how often samples come), and its SampleSource — and one entry in SourceCatalogue
// below. The first entry is the default.

#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <variant>

#include "rpem/daemon/can_source.hpp"
#include "rpem/daemon/signal_map_source.hpp"
#include "rpem/daemon/sim_source.hpp"
#include "rpem/daemon/vesc_source.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::daemon {

template <class... Kinds>
struct Catalogue {
  /// A source's configuration: its kind is the alternative held.
  using Options = std::variant<typename Kinds::Options...>;

  /// Reads a `source` section (its `type` is required).
  [[nodiscard]] static Options parse(io::YamlMap& source, const std::string& base_dir) {
    return parse(source, base_dir, std::index_sequence_for<Kinds...>{});
  }
  [[nodiscard]] static const char* type(const Options& o) { return type(o, std::index_sequence_for<Kinds...>{}); }
  /// The kind of sample the configured source produces (which estimator the loop runs).
  [[nodiscard]] static SampleKind sample_kind(const Options& o) noexcept {
    return sample_kind(o, std::index_sequence_for<Kinds...>{});
  }
  /// How far apart the configured source's samples come, where it sets that (a kind with sample_spacing()).
  [[nodiscard]] static SampleSpacing sample_spacing(const Options& o) noexcept {
    return sample_spacing(o, std::index_sequence_for<Kinds...>{});
  }
  /// Builds the configured source (throws io::ConfigError if it cannot be, e.g. a bad scenario).
  [[nodiscard]] static std::unique_ptr<SampleSource> make(const Options& o) {
    return make(o, std::index_sequence_for<Kinds...>{});
  }

 private:
  template <std::size_t I>
  using Kind = std::tuple_element_t<I, std::tuple<Kinds...>>;

  template <std::size_t... I>
  static SampleKind sample_kind(const Options& o, std::index_sequence<I...>) noexcept {
    SampleKind kind = SampleKind::kPhase;
    ((o.index() == I ? (kind = Kind<I>::sample_kind(*std::get_if<I>(&o)), 0) : 0), ...);
    return kind;
  }

  template <std::size_t... I>
  static SampleSpacing sample_spacing(const Options& o, std::index_sequence<I...>) noexcept {
    SampleSpacing spacing;
    auto one = [&]<std::size_t K>(std::integral_constant<std::size_t, K>) {
      if constexpr (requires(const typename Kind<K>::Options& k) { Kind<K>::sample_spacing(k); }) {
        if (o.index() == K) spacing = Kind<K>::sample_spacing(*std::get_if<K>(&o));
      }
    };
    (one(std::integral_constant<std::size_t, I>{}), ...);
    return spacing;
  }

  template <std::size_t... I>
  static Options parse(io::YamlMap& source, const std::string& base_dir, std::index_sequence<I...>) {
    const std::string chosen = source.choice("type", {Kinds::kType...});
    Options options;
    auto one = [&]<std::size_t K>(std::integral_constant<std::size_t, K>) {
      typename Kind<K>::Options o{};
      if (auto section = source.optional_map(Kind<K>::kType)) o = Kind<K>::parse(*section, base_dir);
      if (chosen == Kind<K>::kType) options.template emplace<K>(o);
    };
    (one(std::integral_constant<std::size_t, I>{}), ...);
    source.finish();
    return options;
  }
  template <std::size_t... I>
  static const char* type(const Options& o, std::index_sequence<I...>) {
    const char* name = "";
    ((o.index() == I ? (name = Kind<I>::kType, 0) : 0), ...);
    return name;
  }
  template <std::size_t... I>
  static std::unique_ptr<SampleSource> make(const Options& o, std::index_sequence<I...>) {
    std::unique_ptr<SampleSource> source;
    ((o.index() == I ? (source = Kind<I>::make(std::get<I>(o)), 0) : 0), ...);
    return source;
  }
};

using SourceCatalogue = Catalogue<SimSource, CanSource, VescSource, SignalMapSource>;
using SourceConfig = SourceCatalogue::Options;

}  // namespace rpem::daemon
