// One writer per output folder: pdsolve takes the lock that make, peridyn's Case.run and the
// benchmarks take (flock(2) on <output_dir>/.lock; pipeline/output_lock.py, the Makefile).
#pragma once
#include <filesystem>
#include <string>

#include "core/error.hpp"

namespace pd {

// Another run holds the folder: the message names the holder (what its .lock says) and what to do.
// pdsolve exits with 75 (EX_TEMPFAIL), as make does on the same lock.
struct FolderInUse : Error {
  using Error::Error;
};

// Held for as long as the object lives. Before, a pdsolve started by hand (as its own interrupt
// message suggests) beside a `make case=X` solving into the same folder wrote NUL bytes into
// history.csv and deleted the other run's frames (issue 36).
class OutputLock {
 public:
  // Takes the lock of `folder` (created if missing) and writes `who` into it, or finds that the
  // process that started this one holds it for us: PD_LOCK_FD names the descriptor make and peridyn
  // hand down. That descriptor open on the folder's .lock: it must hold the lock (flock on it
  // succeeds only if its open file holds it or nobody does). Closed, or its number reused for
  // another file (an mpiexec between make and the ranks does both): the parent's word is taken, so
  // PD_LOCK_FD set by hand skips the lock. Throws FolderInUse.
  OutputLock(const std::filesystem::path& folder, const std::string& who);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  int fd_ = -1;  // this process's own descriptor of the lock, or -1 when a parent's holds it
};

}  // namespace pd
