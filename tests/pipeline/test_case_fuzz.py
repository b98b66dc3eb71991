"""A short, fixed-seed run of the case-file fuzzer (pipeline/fuzz_case.py; `make fuzz` runs it for
FUZZ_SECONDS): every mutated case file loads or is refused with a CaseError, none ends in another
exception or takes more than 5 s."""
import os
import subprocess
import sys

from pipeline.fuzz_case import ROOT, fuzz, mutate, seeds


def test_mutated_case_files_load_or_fail_cleanly():
    result = fuzz(seconds=60, seed=17, max_runs=400)
    assert result["runs"] == 400
    # The mutations reach both sides of the contract: some files still load, most are refused.
    assert 0 < result["loaded"] < result["runs"]
    assert not result["findings"], result["findings"][0][1]


def test_the_mutations_are_reproducible_from_the_seed():
    import random
    corpus = seeds()
    assert len(corpus) >= 9
    first = [mutate(corpus[0], corpus, random.Random(5)) for _ in range(3)]
    again = [mutate(corpus[0], corpus, random.Random(5)) for _ in range(3)]
    assert first == again and any(m != corpus[0] for m in first)


SEEDS_IN_A_SUBPROCESS = """
import os, resource, sys
resource.setrlimit(resource.RLIMIT_AS, (1 << 30, resource.RLIM_INFINITY))  # the old reader ate 23.7 GB
from pipeline import fuzz_case
fuzz_case.ROOT = sys.argv[1]
for data in fuzz_case.seeds():
    print(len(data), data[:12])
"""


def test_seeds_are_small_regular_files_inside_their_folder(tmp_path):
    """A seed linked to /dev/zero drove the fuzzer to 23.7 GB (issue 36, item 15); a FIFO would block
    it, a link out of cases/ reads another file, a huge one is no case file. Only the real seeds and a
    link within cases/ are read; the rest are skipped with their reason."""
    cases = tmp_path / "cases"
    for name in ("plate", "zero", "fifo", "huge", "outside", "alias"):
        (cases / name).mkdir(parents=True)
    (cases / "plate" / "plate.yaml").write_text("dimension: 2\n")
    os.symlink("/dev/zero", cases / "zero" / "zero.yaml")
    os.mkfifo(cases / "fifo" / "fifo.yaml")
    (cases / "huge" / "huge.yaml").write_bytes(b"#" * (2 << 20))
    (tmp_path / "secret.yaml").write_text("not a case\n")
    os.symlink(tmp_path / "secret.yaml", cases / "outside" / "outside.yaml")
    os.symlink(cases / "plate" / "plate.yaml", cases / "alias" / "alias.yaml")
    result = subprocess.run([sys.executable, "-c", SEEDS_IN_A_SUBPROCESS, str(tmp_path)], cwd=ROOT,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.splitlines() == ["13 b'dimension: 2'", "13 b'dimension: 2'"]  # alias, plate
    skipped = []
    seeds(str(tmp_path), skipped)
    assert sorted(skipped) == sorted([
        f"{cases}/fifo/fifo.yaml: a FIFO (named pipe), not a regular file",
        f"{cases}/huge/huge.yaml: larger than 1024 kB",
        f"{cases}/outside/outside.yaml: a link out of {cases} (to {tmp_path / 'secret.yaml'})",
        f"{cases}/zero/zero.yaml: a link out of {cases} (to /dev/zero)"])


LIMIT_IN_A_SUBPROCESS = """
import resource, sys
from pipeline import fuzz_case, fuzz_cli
fuzz_case.main(["--seconds", "0", "--seed", "1"])
print(resource.getrlimit(resource.RLIMIT_AS)[0] >> 20)
if resource.getrlimit(resource.RLIMIT_AS)[0] == resource.RLIM_INFINITY:
    print("no limit")  # (not allocating 3 GB then: the machine is shared)
else:
    try:
        block = bytearray(3 << 30)
        print("allocated 3 GB")
    except MemoryError:
        print("MemoryError")
fuzz_cli.main(["--seconds", "0", "--seed", "1", "--solver", "/nonexistent"])
print(resource.getrlimit(resource.RLIMIT_AS)[0] >> 20)
"""


def test_the_python_fuzzers_bound_their_own_memory():
    """`make fuzz` runs both Python fuzzers' main(): each caps its address space (the libFuzzer runs
    have -rss_limit_mb=2048), so a runaway input ends in a MemoryError, not the OOM killer."""
    result = subprocess.run([sys.executable, "-c", LIMIT_IN_A_SUBPROCESS], cwd=ROOT, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    lines = [line for line in result.stdout.splitlines() if not line.startswith(("pd_fuzz", "pdsolve"))]
    assert lines == ["2048", "MemoryError", "2048"]  # fuzz_cli never raises the limit (its own: 4096)
