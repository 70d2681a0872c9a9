#pragma once
// What a source's options read from a file when the configuration was parsed (a scenario, a signal map),
// kept so that the source runs on exactly what was checked: the file is read once. Read again when the
// source was made, an edit in between would start rpemd on a file nothing had checked.

#include <cassert>
#include <memory>
#include <utility>

namespace rpem::daemon {

template <class T>
class ReadAtParse {
 public:
  ReadAtParse() = default;  ///< nothing read: options made without a parse (the defaults)
  explicit ReadAtParse(T content) : content_(std::make_shared<const T>(std::move(content))) {}

  [[nodiscard]] bool has_value() const noexcept { return content_ != nullptr; }
  [[nodiscard]] const std::shared_ptr<const T>& shared() const noexcept { return content_; }
  [[nodiscard]] const T& operator*() const noexcept {
    assert(content_ && "read at parse");
    return *content_;
  }

  /// The file's path, beside it in the options, is what a reload compares: the content is not.
  bool operator==(const ReadAtParse& /*other*/) const noexcept { return true; }

 private:
  std::shared_ptr<const T> content_;
};

}  // namespace rpem::daemon
