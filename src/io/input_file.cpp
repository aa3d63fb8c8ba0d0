#include "extwrench/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "extwrench/core/error.hpp"

namespace extwrench {
namespace {

const char* kind(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO or pipe";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a plain file";
}

// Throws unless `st` describes a regular file within the cap.
void check_stat(const struct stat& st, const std::string& name, const std::string& what,
                std::uintmax_t max_bytes) {
  if (S_ISDIR(st.st_mode)) throw Error(name + ": the " + what + " file is a directory");
  if (!S_ISREG(st.st_mode)) {
    throw Error(name + ": the " + what + " file is not a regular file (" + kind(st.st_mode) +
                "); give a regular file");
  }
  if (static_cast<std::uintmax_t>(st.st_size) > max_bytes) {
    throw Error(name + ": the " + what + " file is larger than " + std::to_string(max_bytes) +
                " bytes (the limit, docs/cli.md)");
  }
}

[[noreturn]] void fail_errno(const std::string& name, const std::string& what, int err) {
  if (err == ENOENT || err == ENOTDIR) throw Error(name + ": no such " + what + " file");
  throw Error(name + ": cannot open the " + what + " file: " + std::strerror(err));
}

// Closes the descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

void check_input_file(const std::filesystem::path& path, const std::string& what,
                      std::uintmax_t max_bytes) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail_errno(path.string(), what, errno);
  check_stat(st, path.string(), what, max_bytes);
}

std::string read_input_file(const std::filesystem::path& path, const std::string& what,
                            std::uintmax_t max_bytes) {
  const std::string name = path.string();
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (f.fd < 0) fail_errno(name, what, errno);
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) fail_errno(name, what, errno);
  check_stat(st, name, what, max_bytes);
  std::string text;
  text.reserve(static_cast<std::size_t>(st.st_size));
  char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(f.fd, chunk, sizeof chunk);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(name + ": cannot read the " + what + " file: " + std::strerror(errno));
    }
    text.append(chunk, static_cast<std::size_t>(n));
    // The file may grow while it is read.
    if (text.size() > max_bytes) {
      throw Error(name + ": the " + what + " file is larger than " + std::to_string(max_bytes) +
                  " bytes (the limit, docs/cli.md)");
    }
  }
  return text;
}

std::string xml_given_instead(const std::string& what_belongs) {
  return "this is XML (a URDF or MJCF robot file?), but " + what_belongs;
}

}  // namespace extwrench
