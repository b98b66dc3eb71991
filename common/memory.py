"""The memory of this machine as our tools see it: how much is available now, and a ceiling on a
tool's own address space.

available_memory() is MemAvailable of /proc/meminfo: the work plan of pipeline/cost.py, the mesh
readers' size check and the gmsh sandbox's cap all weigh a job against it.

limit_address_space() bounds a long-running Python tool (the fuzzers of `make fuzz`). A fuzzer's
input can make it allocate without end: a seed of pipeline/fuzz_case.py that was a link to
/dev/zero drove it to 23.7 GB and the OOM killer (issue 36, item 15). The libFuzzer runs of the
Makefile stop at -rss_limit_mb=2048; the Python fuzzers set RLIMIT_AS on themselves (Linux does not
enforce RLIMIT_RSS), so an allocation past the limit is a MemoryError — a finding with its input —
and not the machine's memory. The limit is inherited by child processes (fuzz_cli's pdsolve runs).
"""
from __future__ import annotations

import math
import resource


def available_memory() -> float:
    """MemAvailable of /proc/meminfo [bytes], or infinity where it cannot be read."""
    try:
        with open("/proc/meminfo", encoding="ascii") as stream:
            for line in stream:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return math.inf


def limit_address_space(megabytes: int) -> int:
    """Lower the soft RLIMIT_AS to `megabytes` (never raise it); returns the limit now in force [bytes]."""
    wanted = megabytes << 20
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        wanted = min(wanted, hard)
    if soft == resource.RLIM_INFINITY or soft > wanted:
        resource.setrlimit(resource.RLIMIT_AS, (wanted, hard))
        soft = wanted
    return soft
