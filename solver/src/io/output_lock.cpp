// The output folder's lock (io/output_lock.hpp): flock(2) on <folder>/.lock.
#include "io/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

namespace pd {

namespace {

// What the holder wrote into the lock (first line, at most 400 bytes), for the refusal.
std::string holder(int fd) {
  char text[400];
  const ssize_t n = ::pread(fd, text, sizeof text, 0);
  std::string line = n > 0 ? std::string(text, static_cast<std::size_t>(n)) : std::string();
  line = line.substr(0, line.find('\n'));
  return line.empty() ? "unknown" : line;
}

FolderInUse in_use(const std::filesystem::path& folder, int fd) {
  std::string shown = folder.lexically_normal().string();  // "out/x/." → "out/x/"
  if (shown.size() > 1 && shown.back() == '/') shown.pop_back();
  return FolderInUse(shown + "/ is in use by another run (" + holder(fd) +
                     "); wait for it to finish (or stop it: its Ctrl-C writes a checkpoint), or write into "
                     "another folder");
}

// The descriptor PD_LOCK_FD names, or -1 if it names none (unset, not a number).
int inherited_descriptor() {
  const char* text = std::getenv("PD_LOCK_FD");
  if (!text || !*text) return -1;
  char* end = nullptr;
  const long fd = std::strtol(text, &end, 10);
  return *end == '\0' && fd >= 0 && fd < 1 << 20 ? static_cast<int>(fd) : -1;
}

}  // namespace

OutputLock::OutputLock(const std::filesystem::path& folder, const std::string& who) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw Error(folder.string() + ": cannot create the output folder: " + ec.message());
  const std::filesystem::path path = folder / ".lock";
  if (const int inherited = inherited_descriptor(); inherited >= 0) {
    struct stat handed {}, file {};
    const bool the_lock = ::fstat(inherited, &handed) == 0 && ::stat(path.c_str(), &file) == 0 &&
                          handed.st_dev == file.st_dev && handed.st_ino == file.st_ino;
    if (!the_lock) return;  // closed on the way, its number reused (mpiexec does both): the parent's word
    if (::flock(inherited, LOCK_EX | LOCK_NB) == 0) return;  // held by the open file we share
    throw in_use(folder, inherited);
  }
  // O_NOFOLLOW: a .lock planted as a symbolic link must not make us write into its target.
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(path.string() + ": cannot open the output folder's lock: " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const FolderInUse refused = in_use(folder, fd_);
    ::close(fd_);
    fd_ = -1;
    throw refused;
  }
  char since[16];
  const std::time_t now = std::time(nullptr);
  std::strftime(since, sizeof since, "%H:%M:%S", std::localtime(&now));
  const std::string line = "pid " + std::to_string(::getpid()) + ", " + who + ", since " + since + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::write(fd_, line.data(), line.size()) < 0) {
    // The lock is held; only the note for a refused writer is missing.
  }
}

OutputLock::~OutputLock() {
  if (fd_ >= 0) ::close(fd_);  // closing our descriptor of the open file releases the lock
}

}  // namespace pd
