// Whole input files, regular files only (read_file.hpp).
#include "io/read_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/error.hpp"

namespace pd {

std::string read_whole_file(const std::filesystem::path& path, const std::string& what) {
  const std::string file = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw Error(file + ": cannot open " + what + " for reading: " + std::strerror(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
    const bool directory = S_ISDIR(info.st_mode);
    ::close(fd);
    throw Error(file + ": " + (directory ? "a directory" : "not a regular file") + ", not " + what +
                "; give the path of the file");
  }
  std::string bytes;
  try {
    bytes.resize(static_cast<std::size_t>(info.st_size));
  } catch (const std::bad_alloc&) {
    ::close(fd);
    throw Error(file + ": " + std::to_string(info.st_size) + " bytes, more than this machine's memory can hold " +
                "for " + what);
  }
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t r = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      const int error_number = errno;
      ::close(fd);
      throw Error(file + ": cannot read " + what + ": " + std::strerror(error_number));
    }
    if (r == 0) break;  // shrank while read: the readers report what is missing
    done += static_cast<std::size_t>(r);
  }
  bytes.resize(done);
  ::close(fd);
  return bytes;
}

}  // namespace pd
