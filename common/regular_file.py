"""Open an input file only if it is a regular file, without ever blocking on it.

A plain open() of a FIFO (named pipe) waits for a writer that never comes: `make check` with a FIFO
as the case file hung (issue 36, item 11), and a device such as /dev/zero streams bytes forever. So
the file is stat'ed first, then opened with O_NONBLOCK (a FIFO opens at once that way; on a regular
file the flag changes nothing) and fstat'ed again: a path swapped for a FIFO between the two calls is
refused too. Symbolic links are followed: a link to a regular file is a regular file.
"""
from __future__ import annotations

import os
import stat

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


class NotRegularFile(OSError):
    """The path exists but is no regular file; str() says what it is."""


def kind_of(mode: int) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"


def _refuse_unless_regular(path: str, mode: int):
    if not stat.S_ISREG(mode):
        raise NotRegularFile(f"{path}: {kind_of(mode)}, not a regular file")


def open_regular(path: str):
    """A binary file object for reading `path`. A FIFO, device, socket or directory raises
    NotRegularFile ("<path>: a FIFO (named pipe), not a regular file") before any read and without
    blocking; other OSErrors (missing, no permission) come as open() raises them."""
    _refuse_unless_regular(path, os.stat(path).st_mode)
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        _refuse_unless_regular(path, os.fstat(fd).st_mode)
    except BaseException:
        os.close(fd)
        raise
    return os.fdopen(fd, "rb")


def read_regular(path: str, limit: int) -> bytes:
    """At most limit + 1 bytes of `path` (so that the caller can tell "larger than limit"), with the
    errors of open_regular."""
    with open_regular(path) as stream:
        return stream.read(limit + 1)
