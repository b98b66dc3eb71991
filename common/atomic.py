"""The one atomic-file writer of the Python side: write under a temporary name in the target's
directory, then rename into place, so that an interrupted stage never leaves a half-written file.

- The file gets the mode a plain open() would give it (0666 less the umask), not mkstemp's 0600.
- The temporary name carries the writer's process id, `.tmp-<pid>-XXXX-<name>`. SIGTERM (what
  `timeout`, CI runners and SLURM send) is turned into an exit while a file is being written, so the
  temporary file is removed as on any error; one left by a process killed outright (kill -9) is
  removed by the next writer of the same file once that process is gone (issue 17, item 7).
- A full disk (ENOSPC, EDQUOT) is a WriteError saying which file and how much space is free, not a
  traceback (issue 17, item 6); nothing is left behind.
"""
from __future__ import annotations

import contextlib
import errno
import glob
import os
import shutil
import signal
import tempfile
import threading

DISK_FULL_EXIT = 3  # the solver's exit code for a run that failed, disk full included


class WriteError(Exception):
    """A file could not be written (a full disk, a quota): the message says which and what to do."""


def _umask() -> int:
    mask = os.umask(0)  # the only way to read it; set straight back
    os.umask(mask)
    return mask


def free_megabytes(directory: str) -> float:
    try:
        return shutil.disk_usage(directory).free / 1e6
    except OSError:
        return 0.0


def disk_full_message(path: str) -> str:
    directory = os.path.dirname(os.path.abspath(path))
    return (f"disk full writing {path}: {free_megabytes(directory):.0f} MB free in {directory}; "
            "free some space and run make again")


class _Terminated(SystemExit):
    """SIGTERM while a file is written: unwinds like an error (temporary files go), exits 128 + 15."""


_writing = 0        # atomic_path blocks open in this process (they nest)
_previous = None    # the SIGTERM handler before the outermost one


def _on_sigterm(signum, frame):
    raise _Terminated(128 + signum)


def _enter_signal_guard():
    global _writing, _previous
    if threading.current_thread() is not threading.main_thread():
        return False  # only the main thread may set handlers; it gets the signal anyway
    if _writing == 0:
        current = signal.getsignal(signal.SIGTERM)
        if current is not signal.SIG_DFL:  # the program has its own handler (or ignores SIGTERM)
            return False
        _previous = signal.signal(signal.SIGTERM, _on_sigterm)
    _writing += 1
    return True


def _leave_signal_guard():
    global _writing
    _writing -= 1
    if _writing == 0:
        signal.signal(signal.SIGTERM, _previous)


def _process_gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False


def remove_stale_temporaries(path: str):
    """Remove `.tmp-<pid>-*-<name>` files next to `path` whose writer process is gone."""
    directory = os.path.dirname(os.path.abspath(path))
    pattern = os.path.join(glob.escape(directory), ".tmp-*-" + glob.escape(os.path.basename(path)))
    for stale in glob.glob(pattern):
        pid_text = os.path.basename(stale)[len(".tmp-"):].split("-", 1)[0]
        if pid_text.isdigit() and int(pid_text) != os.getpid() and _process_gone(int(pid_text)):
            with contextlib.suppress(OSError):
                os.unlink(stale)


@contextlib.contextmanager
def atomic_path(path: str):
    """Yield a temporary path next to `path`; on success rename it to `path`, on error delete it.

    The temporary name ends with the final name (…-energy.png, …-mesh.msh) so that writers that
    look at the extension (matplotlib, gmsh) see the right one.
    """
    directory = os.path.dirname(os.path.abspath(path))
    guarded = _enter_signal_guard()
    try:
        try:
            os.makedirs(directory, exist_ok=True)
            remove_stale_temporaries(path)
            fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".tmp-{os.getpid()}-",
                                       suffix="-" + os.path.basename(path))
            os.close(fd)
        except OSError as err:
            if err.errno in (errno.ENOSPC, errno.EDQUOT):
                raise WriteError(disk_full_message(path)) from None
            raise
        try:
            yield tmp
            os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
            os.replace(tmp, path)
        except BaseException as err:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            if _is_disk_full(err):
                raise WriteError(disk_full_message(path)) from None
            raise
    finally:
        if guarded:
            _leave_signal_guard()


def _is_disk_full(err: BaseException) -> bool:
    """ENOSPC/EDQUOT raised directly, or wrapped by a library (matplotlib, meshio) as its cause."""
    for _ in range(10):  # a chain of a few wrapped exceptions at most
        if err is None:
            return False
        if isinstance(err, OSError) and err.errno in (errno.ENOSPC, errno.EDQUOT):
            return True
        err = err.__cause__ or err.__context__
    return False


def write_atomically(path: str, data: str | bytes):
    """Write text (UTF-8) or bytes to `path` atomically."""
    binary = isinstance(data, bytes)
    with atomic_path(path) as tmp, open(tmp, "wb" if binary else "w",
                                        **({} if binary else {"encoding": "utf-8", "newline": ""})) as stream:
        stream.write(data)
