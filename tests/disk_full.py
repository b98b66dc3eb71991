"""Run a command with a folder replaced by a small, nearly full tmpfs, to test what each stage does
when the disk fills (issue 17, item 6).

The tmpfs is mounted in a mount namespace of its own (`unshare --map-root-user --mount`), so the
test needs no root and changes nothing outside its command; the kernel's own ENOSPC is what the
writers meet, no injection. Where user namespaces are disabled the tests say so and skip.
"""
import shlex
import subprocess

import pytest


def run_on_small_disk(folder, command, size_kb=64, timeout=300, cwd=None, env=None, keep=None):
    """Run `command` (a list) with `folder` a fresh tmpfs of size_kb; return (code, stdout, stderr,
    the names left in folder). With `keep`, a folder: what the command left is copied there."""
    copy = f"cp -a {shlex.quote(str(folder))}/. {shlex.quote(str(keep))}/\n" if keep else ""
    script = (f"mount -t tmpfs -o size={size_kb}k pdtest {shlex.quote(str(folder))} || exit 97\n"
              f"{shlex.join(command)}\ncode=$?\n{copy}echo '--left--'\nls -A {shlex.quote(str(folder))}\n"
              "exit $code\n")
    result = subprocess.run(["unshare", "--map-root-user", "--mount", "sh", "-c", script], cwd=cwd, env=env,
                            capture_output=True, text=True, timeout=timeout)
    if result.returncode == 97 or "unshare:" in result.stderr:
        pytest.skip(f"cannot mount a tmpfs in a user namespace here: {result.stderr.strip()[:200]}")
    out, _, left = result.stdout.partition("--left--\n")
    return result.returncode, out, result.stderr, left.split()
