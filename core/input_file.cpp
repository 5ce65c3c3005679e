#include "core/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace palpate {
namespace {

// Opens path read-only without blocking and checks the open file; returns the fd (>= 0) or -1 with *error set.
int open_checked(const std::string& path, const std::string& what, int64_t max_bytes, int64_t* size, Error* error) {
  const std::string who = what + " '" + path + "': ";
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int e = errno;
    *error = e == ENOENT ? make_error(who, "file not found") : e == EISDIR ? make_error(who, "is a directory, not a regular file")
                                                                           : make_error(who, std::strerror(e));
    return -1;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    *error = make_error(who, std::strerror(errno));
  } else if (S_ISDIR(st.st_mode)) {
    *error = make_error(who, "is a directory, not a regular file");
  } else if (!S_ISREG(st.st_mode)) {
    *error = make_error(who, "is not a regular file (a device, FIFO or socket)");
  } else if (st.st_size == 0) {
    *error = make_error(who, "file is empty");
  } else if (st.st_size > max_bytes) {
    *error = make_error(who, std::to_string(st.st_size), " bytes, more than the limit of ", std::to_string(max_bytes));
  } else {
    *size = st.st_size;
    return fd;
  }
  ::close(fd);
  return -1;
}

}  // namespace

Result<int64_t> check_input_file(const std::string& path, const std::string& what, int64_t max_bytes) {
  int64_t size = 0;
  Error error;
  const int fd = open_checked(path, what, max_bytes, &size, &error);
  if (fd < 0) return error;
  ::close(fd);
  return size;
}

Result<std::string> read_input_file(const std::string& path, const std::string& what, int64_t max_bytes) {
  int64_t size = 0;
  Error error;
  const int fd = open_checked(path, what, max_bytes, &size, &error);
  if (fd < 0) return error;
  std::string text(static_cast<std::size_t>(size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      return make_error(what, " '", path, "': ", std::strerror(e));
    }
    if (n == 0) break;  // shrank while read
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  text.resize(got);
  if (text.empty()) return make_error(what, " '", path, "': file is empty");
  return text;
}

}  // namespace palpate
