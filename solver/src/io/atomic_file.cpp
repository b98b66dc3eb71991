// Whole-or-absent files: written under a temporary name beside the target, then renamed into place.
#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace pd {

void throw_write_error(const std::filesystem::path& file, const std::string& what, int error_number,
                       std::size_t bytes) {
  if (error_number == ENOSPC || error_number == EDQUOT) {
    const double megabytes = std::max(1.0, std::ceil(static_cast<double>(bytes) / 1e6));
    throw DiskFull("disk full writing " + file.string() + ": free " + std::to_string(static_cast<long long>(megabytes)) +
                   " MB and run make again");
  }
  throw Error(file.string() + ": " + what + ": " + std::strerror(error_number));
}

void write_file_atomically(const std::filesystem::path& path, const std::vector<std::string_view>& pieces,
                           Durability durability) {
  const std::filesystem::path tmp = path.string() + ".part";
  std::size_t total = 0;
  for (const std::string_view piece : pieces) total += piece.size();
  // POSIX calls, not an ofstream: the failure's errno tells a full disk from other errors.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw_write_error(tmp, "cannot open for writing", errno, total);
  auto fail = [&](const char* what) {
    const int error_number = errno;
    ::close(fd);
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);  // no half-written .part left behind
    throw_write_error(error_number == ENOSPC || error_number == EDQUOT ? path : tmp, what, error_number, total);
  };
  // Piece by piece from where the data lie: a frame's arrays are not first copied into one string.
  for (const std::string_view piece : pieces) {
    std::size_t done = 0;
    while (done < piece.size()) {
      const ssize_t w = ::write(fd, piece.data() + done, piece.size() - done);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) {
        if (w == 0) errno = ENOSPC;  // write() making no progress: the disk is full
        fail("write failed");
      }
      done += static_cast<std::size_t>(w);
    }
  }
  if (durability == Durability::synced && ::fsync(fd) != 0) fail("fsync failed");
  if (::close(fd) != 0) {
    const int error_number = errno;
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw_write_error(error_number == ENOSPC || error_number == EDQUOT ? path : tmp, "write failed", error_number, total);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw Error(path.string() + ": cannot rename " + tmp.string() + " into place: " + ec.message());
  }
  if (durability == Durability::synced) {
    // The rename is an entry of the folder: flushed with it. A folder that cannot be opened or
    // flushed (some network file systems) leaves the file as durable as the file system makes it.
    const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
    const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) {
      ::fsync(dir);
      ::close(dir);
    }
  }
}

void write_file_atomically(const std::filesystem::path& path, const std::string& text, Durability durability) {
  write_file_atomically(path, std::vector<std::string_view>{text}, durability);
}

}  // namespace pd
