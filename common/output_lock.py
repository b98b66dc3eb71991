"""One writer at a time per output folder: the lock make, peridyn's Case.run, validation and bench
all take (issue 36, item 5).

The lock is flock(2) on <folder>/.lock, the same lock the Makefile takes with flock(1) (its
`pd-case-lock` rule), so a `make case=X` and a `Case.run` into out/X/ exclude each other. Before,
Case.run took none: two runs into one folder both reported the second run's results, and one beside
`make case=membrane` wrote NUL bytes into history.csv. The file holds a line saying who holds it,
which the refused writer prints. A lock of flock(2) goes with the last process holding the open
file: a writer killed by SIGKILL frees it, and a solver started under it (pass_fds) keeps it while
it runs.
"""
from __future__ import annotations

import contextlib
import fcntl
import os
import sys
import time


class FolderInUse(RuntimeError):
    """Another run holds the folder's lock: the message names it and says what to do."""


def _holder(fd: int) -> str:
    try:
        return os.pread(fd, 400, 0).decode("utf-8", "replace").strip() or "unknown"
    except OSError:
        return "unknown"


def _handed_down(path: str) -> int | None:
    """The descriptor of `path` that the process which started this one holds the lock through
    (PD_LOCK_FD, set by make and peridyn, as pdsolve reads it: io/output_lock.hpp; -1 if that
    descriptor was closed or reused on the way: the parent's word), or None (no PD_LOCK_FD) to take
    our own. A descriptor of the lock that does not hold it (another run does): FolderInUse."""
    text = os.environ.get("PD_LOCK_FD", "")
    if not text.isdigit():
        return None
    fd = int(text)
    try:
        handed, own = os.fstat(fd), os.stat(path)
    except OSError:
        handed = own = None
    if handed is None or (handed.st_dev, handed.st_ino) != (own.st_dev, own.st_ino):
        return -1   # closed on the way, its number reused: the parent's word, as pdsolve takes it
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # succeeds on the open file that holds it
    except BlockingIOError:
        raise FolderInUse(f"error: {os.path.dirname(path)}/ is in use by another run ({_holder(fd)}); wait for "
                          "it to finish, or write into another folder") from None
    return fd


@contextlib.contextmanager
def output_lock(folder: str, who: str, wait: float = 0.0):
    """Hold <folder>/.lock for the `with` block; yields the lock's file descriptor (hand it to a
    child with subprocess's pass_fds to keep the folder locked while that child lives).

    who: what holds it, written into the file for a refused writer to read (e.g. "peridyn Case.run").
    wait: seconds to wait for another holder to finish (0: refuse at once, as make's LOCK_WAIT=0).
    """
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, ".lock")
    handed = _handed_down(path)
    if handed is not None:
        yield handed
        return
    # O_NOFOLLOW: a .lock planted as a symbolic link must not make us write into its target.
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_APPEND | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
    try:
        deadline = time.monotonic() + wait
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    raise FolderInUse(
                        f"error: {folder}/ is in use by another run ({_holder(fd)}); wait for it to finish "
                        f"(or stop it: its Ctrl-C writes a checkpoint), or write into another folder") from None
                time.sleep(0.2)
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"pid {os.getpid()}, {who}, since {time.strftime('%H:%M:%S')}\n".encode())
        except OSError:
            pass  # a full disk: the lock is held, only the note for a refused writer is missing
        yield fd
    finally:
        os.close(fd)  # closing the last descriptor of the open file releases the lock


def exit_code(main) -> int:
    """main()'s exit code for a command line; a folder in use is its one-line message on stderr and
    exit 75 (EX_TEMPFAIL, make's lock's code too), with no traceback."""
    try:
        return main() or 0
    except FolderInUse as error:
        print(error, file=sys.stderr)
        return 75
