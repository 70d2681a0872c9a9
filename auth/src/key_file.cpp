#include "rpem/auth/key_file.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <limits>
#include <string_view>

#include "rpem/core/errno_text.hpp"

namespace rpem::auth {
namespace {

constexpr const char* kMagic = "rpem-key-1";
constexpr std::size_t kMaxFileBytes = 4096;

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// The next whitespace-separated word of `rest`, a view into it (no copy: a key file's text is the key).
std::string_view next_word(std::string_view& rest) {
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::size_t begin = 0;
  while (begin < rest.size() && space(rest[begin])) ++begin;
  std::size_t end = begin;
  while (end < rest.size() && !space(rest[end])) ++end;
  const std::string_view word = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return word;
}

/// Wipes a string that held a key's text when it goes.
struct WipeOnExit {
  std::string& text;
  ~WipeOnExit() { sodium_memzero(text.data(), text.size()); }
};

}  // namespace

Key parse_key(const std::string& text, const std::string& where) {
  auto fail = [&](const std::string& why) {
    return KeyError(where + ": not a key file (" + why + "); expected one line `" + kMagic +
                    " <key id 1..2147483647> <64 hex digits>`, as `rpem keygen` writes");
  };
  std::string_view rest = text;
  const std::string_view magic = next_word(rest), id_word = next_word(rest), hex = next_word(rest);
  if (hex.empty() || magic != kMagic) throw fail("no `" + std::string(kMagic) + "` header");
  if (!next_word(rest).empty()) throw fail("text after the key");
  const std::string id_text(id_word);
  std::int32_t id = 0;
  try {
    std::size_t used = 0;
    const long long value = std::stoll(id_text, &used);
    if (used != id_text.size() || value <= 0 || value > std::numeric_limits<std::int32_t>::max())
      throw std::out_of_range("");
    id = static_cast<std::int32_t>(value);
  } catch (const std::exception&) {
    throw fail("key id `" + id_text + "` is not a whole number in 1..2147483647");
  }
  if (hex.size() != 2 * kKeyBytes) throw fail("the key has " + std::to_string(hex.size()) + " hex digits, not 64");
  // Decoded straight into the key's locked memory.
  return Key::filled(id, [&](std::span<std::uint8_t, kKeyBytes> bytes) {
    for (std::size_t k = 0; k < kKeyBytes; ++k) {
      const int hi = hex_digit(hex[2 * k]), lo = hex_digit(hex[2 * k + 1]);
      if (hi < 0 || lo < 0) throw fail("a non-hex digit in the key");
      bytes[k] = static_cast<std::uint8_t>(hi * 16 + lo);
    }
  });
}

std::string format_key(const Key& key) {
  std::string text = std::string(kMagic) + " " + std::to_string(key.id()) + " ";
  const std::size_t at = text.size();
  text.resize(at + 2 * kKeyBytes + 1);  // the hex written in place, with sodium_bin2hex's terminating NUL
  sodium_bin2hex(text.data() + at, 2 * kKeyBytes + 1, key.bytes().data(), key.bytes().size());
  text.back() = '\n';
  return text;
}

Key load_key_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw KeyError(path + ": cannot open the key file: " + core::errno_text(errno));
  struct stat st {};
  std::string text;
  std::string problem;
  if (::fstat(fd, &st) != 0) {
    problem = std::string("stat: ") + core::errno_text(errno);
  } else if (!S_ISREG(st.st_mode)) {
    problem = "not a regular file";
  } else if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    problem =
        std::string("mode ") + mode + " lets its group or others at it; a key file must be the owner's alone (chmod 600)";
  } else if (st.st_size > static_cast<off_t>(kMaxFileBytes)) {
    problem = "larger than a key file can be";
  } else {
    text.resize(static_cast<std::size_t>(st.st_size));
    std::size_t got = 0;
    while (got < text.size()) {
      const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += static_cast<std::size_t>(n);
    }
    text.resize(got);
  }
  ::close(fd);
  const WipeOnExit wipe{text};
  if (!problem.empty()) throw KeyError(path + ": refused: " + problem);
  return parse_key(text, path);
}

Key generate_key(std::int32_t id) {
  if (id <= 0) throw KeyError("a key id is a whole number in 1..2147483647");
  return Key::filled(id, [](std::span<std::uint8_t, kKeyBytes> bytes) { randombytes_buf(bytes.data(), bytes.size()); });
}

void write_key_file(const std::string& path, const Key& key) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw KeyError(path + ": cannot create the key file: " + core::errno_text(errno));
  std::string text = format_key(key);
  const WipeOnExit wipe{text};
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw KeyError(path + ": cannot write the key file");
}

}  // namespace rpem::auth
