#include "rpem/auth/key_file.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>
#include <sstream>

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

}  // namespace

Key parse_key(const std::string& text, const std::string& where) {
  auto fail = [&](const std::string& why) {
    return KeyError(where + ": not a key file (" + why + "); expected one line `" + kMagic +
                    " <key id 1..2147483647> <64 hex digits>`, as `rpem keygen` writes");
  };
  std::istringstream in(text);
  std::string magic, id_text, hex, extra;
  if (!(in >> magic >> id_text >> hex) || magic != kMagic) throw fail("no `" + std::string(kMagic) + "` header");
  if (in >> extra) throw fail("text after the key");
  Key key;
  try {
    std::size_t used = 0;
    const long long id = std::stoll(id_text, &used);
    if (used != id_text.size() || id <= 0 || id > std::numeric_limits<std::int32_t>::max()) throw std::out_of_range("");
    key.id = static_cast<std::int32_t>(id);
  } catch (const std::exception&) {
    throw fail("key id `" + id_text + "` is not a whole number in 1..2147483647");
  }
  if (hex.size() != 2 * kKeyBytes) throw fail("the key has " + std::to_string(hex.size()) + " hex digits, not 64");
  for (std::size_t k = 0; k < kKeyBytes; ++k) {
    const int hi = hex_digit(hex[2 * k]), lo = hex_digit(hex[2 * k + 1]);
    if (hi < 0 || lo < 0) throw fail("a non-hex digit in the key");
    key.bytes[k] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  return key;
}

std::string format_key(const Key& key) {
  std::string hex(2 * kKeyBytes + 1, '\0');
  sodium_bin2hex(hex.data(), hex.size(), key.bytes.data(), key.bytes.size());
  hex.pop_back();
  return std::string(kMagic) + " " + std::to_string(key.id) + " " + hex + "\n";
}

Key load_key_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw KeyError(path + ": cannot open the key file: " + std::strerror(errno));
  struct stat st {};
  std::string text;
  std::string problem;
  if (::fstat(fd, &st) != 0) {
    problem = std::string("stat: ") + std::strerror(errno);
  } else if (!S_ISREG(st.st_mode)) {
    problem = "not a regular file";
  } else if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    problem = std::string("mode ") + mode + " lets its group or others at it; a key file must be the owner's alone (chmod 600)";
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
  if (!problem.empty()) throw KeyError(path + ": refused: " + problem);
  Key key = parse_key(text, path);
  sodium_memzero(text.data(), text.size());
  return key;
}

Key generate_key(std::int32_t id) {
  if (sodium_init() < 0) throw KeyError("libsodium could not be initialised");
  if (id <= 0) throw KeyError("a key id is a whole number in 1..2147483647");
  Key key;
  key.id = id;
  randombytes_buf(key.bytes.data(), key.bytes.size());
  return key;
}

void write_key_file(const std::string& path, const Key& key) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw KeyError(path + ": cannot create the key file: " + std::strerror(errno));
  const std::string text = format_key(key);
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) throw KeyError(path + ": cannot write the key file");
}

}  // namespace rpem::auth
