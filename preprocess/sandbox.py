"""Run a program that reads a case's .geo (gmsh, the gmsh-API probe) in a bubblewrap sandbox.

preprocess/geo_guard.py refuses a .geo that would run a command or write a file, but it reads the
.geo with its own lexer: where gmsh's reads it differently (a string cut at 1023 characters let
`SystemCall` through, issue 36), the guard's check and what gmsh runs part. The sandbox holds
whatever gmsh reads: gmsh runs with
- no network and its own process, IPC and host-name namespaces (--unshare-all), killed with its
  caller (--die-with-parent), in a new terminal session (no keystrokes into the caller's terminal);
- /usr read-only (with the /bin, /lib, /lib64, /sbin links of merged-usr Debian), /proc, /dev, and
  of /etc only the loader's cache and the alternatives links (libblas.so.3): /etc/shadow and the
  rest are not there, nor any home folder: HOME and /tmp are small empty tmpfs;
- no shell: /dev/null over /usr/bin/sh, dash and bash, so gmsh's SystemCall says "Could not find
  /bin/sh: aborting system call" and runs nothing;
- read-only: the case folder and what else the caller names (the repository's Python code for the
  probe); writable: only the fresh empty folder the caller names, from which it moves the result;
- an empty environment but PATH, HOME and OMP_NUM_THREADS; a cap on its address space (RLIMIT_AS).

PD_GMSH_SANDBOX=off runs the program without the sandbox, for a .geo you trust on a machine where
bubblewrap cannot start (docs/reliability.md).
"""
from __future__ import annotations

import functools
import os
import resource
import shutil
import subprocess

from .errors import PreprocessError

BWRAP = "bwrap"
SWITCH = "PD_GMSH_SANDBOX"
TMPFS_BYTES = 64 * 1024 * 1024   # /tmp and HOME inside: room for gmsh's scratch files, not for a disk
SHELLS = ("/usr/bin/sh", "/usr/bin/dash", "/usr/bin/bash")
ETC = ("/etc/ld.so.cache", "/etc/alternatives")
HOME = "/home/sandbox"


def enabled() -> bool:
    value = os.environ.get(SWITCH, "on")
    if value not in ("on", "off", ""):
        raise PreprocessError(f"{SWITCH}={value!r}: expected on or off")
    return value != "off"


def _bwrap_arguments(read_only, writable, cwd) -> list[str]:
    args = ["--unshare-all", "--die-with-parent", "--new-session", "--clearenv",
            "--ro-bind", "/usr", "/usr"]
    for link in ("bin", "lib", "lib64", "sbin"):
        if os.path.islink("/" + link):
            args += ["--symlink", os.readlink("/" + link), "/" + link]
    args += ["--proc", "/proc", "--dev", "/dev",
             "--size", str(TMPFS_BYTES), "--tmpfs", "/tmp", "--size", str(TMPFS_BYTES), "--tmpfs", HOME]
    for path in ETC:
        if os.path.exists(path):
            args += ["--ro-bind", path, path]
    for shell in SHELLS:
        if os.path.exists(shell):
            args += ["--ro-bind", "/dev/null", shell]
    for flag, paths in (("--ro-bind", read_only), ("--bind", writable)):
        for path in paths:
            real = os.path.realpath(path)
            if real == "/":   # a .geo at the root of the file system: that would bind everything
                raise PreprocessError(f"{path}: a case folder must not be the root folder; put the case in a "
                                      "folder of its own")
            # At its real path, and at the path given when that goes through a symbolic link (a
            # tree whose preprocess/ links to the repository's): the program may use either.
            for where in dict.fromkeys((real, os.path.abspath(path))):
                args += [flag, real, where]
    args += ["--setenv", "PATH", "/usr/bin", "--setenv", "HOME", HOME]
    if os.environ.get("OMP_NUM_THREADS"):
        args += ["--setenv", "OMP_NUM_THREADS", os.environ["OMP_NUM_THREADS"]]
    if cwd:
        args += ["--chdir", os.path.realpath(cwd)]
    return args


@functools.lru_cache(maxsize=None)
def _bwrap_works() -> str | None:
    """None if a sandbox starts on this machine, else the reason (bwrap's own words)."""
    exe = shutil.which(BWRAP)
    if exe is None:
        return "bubblewrap (bwrap) is not installed"
    try:
        result = subprocess.run([exe, *_bwrap_arguments((), (), None), "/usr/bin/true"], stdin=subprocess.DEVNULL,
                                capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as err:
        return f"bwrap did not start: {err}"
    if result.returncode != 0:
        return f"bwrap could not make a sandbox: {result.stderr.strip()[:300]}"
    return None


def memory_cap() -> int:
    """The address-space cap of a sandboxed program: half of the memory available now (MemAvailable;
    all of it with FORCE=1, which runs a mesh above the estimate's limits), at least 2 GiB (Python
    with numpy and OpenBLAS maps a few hundred MB it never touches). gmsh meshed a mesh size field
    of 2e-6 m with no cap until its time limit; at the cap its allocations fail and it stops."""
    from common.memory import available_memory

    available = available_memory()
    if available == float("inf"):
        return resource.RLIM_INFINITY
    share = 1.0 if os.environ.get("FORCE") == "1" else 0.5
    return int(max(available * share, 2 * 1024 ** 3))


def run(command: list[str], what: str, *, read_only=(), writable=(), cwd=None, timeout: float,
        memory: int | None = None) -> subprocess.CompletedProcess:
    """subprocess.run(command) in the sandbox (or without it if PD_GMSH_SANDBOX=off), stdin empty,
    output captured as text, stopped after `timeout` s (TimeoutExpired), its address space capped
    at `memory` bytes (default memory_cap()). `what` names the input in errors (the .geo)."""
    cap = memory_cap() if memory is None else memory

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    if enabled():
        problem = _bwrap_works()
        if problem is not None:
            raise PreprocessError(
                f"{what}: gmsh runs in a sandbox, but {problem}. Install it (apt-get install bubblewrap, "
                "pipeline/install-deps.sh does) and, when not running as root, allow unprivileged user "
                "namespaces (sysctl kernel.unprivileged_userns_clone=1 on Debian); or, for a .geo you "
                f"trust, run gmsh without the sandbox with {SWITCH}=off")
        command = [shutil.which(BWRAP), *_bwrap_arguments(read_only, writable, cwd), *command]
        cwd = None
    return subprocess.run(command, cwd=cwd, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                          timeout=timeout, preexec_fn=limit)
