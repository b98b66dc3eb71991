"""A mutation fuzzer for the case-file loader (pipeline.case.load_case: YAML reader + schema check).

    /usr/bin/python3 -m pipeline.fuzz_case --seconds 60 [--seed N] [--artifacts DIR]

It mutates the shipped case files (cases/*/*.yaml, validation/models/*.yaml) at random — bytes
flipped, lines deleted, duplicated, swapped or spliced from another case, YAML tokens inserted
(anchors, aliases, tags, brackets, numbers at the edges of their types) — and loads each result.
The only property checked is the loader's contract: a case file either loads or raises CaseError,
within PER_INPUT_SECONDS. Any other exception (a traceback for the user) or a hang is a finding;
its input is saved to the artifacts folder and the run ends with exit code 1.
`make fuzz` runs it beside the solver's libFuzzer targets; tests/pipeline/test_case_fuzz.py runs a
short fixed-seed version in `make test`.
"""
from __future__ import annotations

import argparse
import glob
import os
import random
import signal
import sys
import tempfile
import time
import traceback

from .case import CaseError, load_case
from common.memory import limit_address_space
from common.regular_file import read_regular
from .yaml_lines import MAX_BYTES

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PER_INPUT_SECONDS = 5
MEMORY_LIMIT_MB = 2048  # as the libFuzzer runs' -rss_limit_mb (Makefile): set by main() on itself

# Tokens that reach the corners of the loader and the schema.
TOKENS = [
    "&a ", "*a", "&b [*a, *a, *a, *a]", "!!python/object:builtins.float ", "!foo ", "!!str ", "!!map ",
    "<<: *a", "<<: {x: 1}", "? [1, 2]\n: 3", "[", "]", "{", "}", "- ", ": ", "---\n", "...\n", "#",
    "\t", "\0", "\xff", "\u2028", "%YAML 1.1\n", "'", '"', "|\n  ", ">-\n  ",
    "5:00", "012", "0o17", "0x1F", "1_000", "0b101", "1e300", "-1e300", "1e-320", ".inf", "-.inf",
    ".nan", "~", "null", "yes", "on", "true", "2001-12-14", "-0", "0", "1", "-1", "2", "3", "2.0",
    "9223372036854775808", "1e30", "x" * 300, "[[0, 1], [1, 2]]", "[[1, 0], [0, 1]]", "{x: 1, y: 2}",
    "[1, 2, 3]", "[]", "{}", "''",
    # whole numbers past a double, past Python's 4300-digit int-string limit, and in hex (issue 36)
    "1" + "0" * 400, "-1" + "0" * 5000, "0x" + "f" * 300,
]


class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout()


def seeds(root: str | None = None, skipped: list | None = None) -> list[bytes]:
    """The shipped case files under `root` (default: the repository), as bytes. A seed must be a regular file of at most
    MAX_BYTES inside its own folder (cases/ or validation/models/): a link out of it, a FIFO, a
    device or a huge file is skipped (its reason appended to `skipped`). Before, every
    cases/*/*.yaml was read whole: a link to /dev/zero took 23.7 GB (issue 36, item 15)."""
    root = ROOT if root is None else root
    out = []
    for folder, pattern in ((os.path.join(root, "cases"), os.path.join("*", "*.yaml")),
                            (os.path.join(root, "validation", "models"), "*.yaml")):
        inside = os.path.realpath(folder)
        for path in sorted(glob.glob(os.path.join(folder, pattern))):
            real = os.path.realpath(path)
            try:
                if os.path.commonpath([real, inside]) != inside:
                    raise OSError(f"{path}: a link out of {folder} (to {real})")
                data = read_regular(path, MAX_BYTES)
                if len(data) > MAX_BYTES:
                    raise OSError(f"{path}: larger than {MAX_BYTES >> 10} kB")
            except OSError as err:  # NotRegularFile included
                if skipped is not None:
                    skipped.append(str(err))
                continue
            out.append(data)
    return out


def mutate(data: bytes, corpus: list[bytes], rng: random.Random) -> bytes:
    """One to four random edits of the file, by byte, by line or by token."""
    for _ in range(rng.randint(1, 4)):
        lines = data.split(b"\n")
        choice = rng.randrange(9)
        if choice == 0 and data:                           # flip a byte
            i = rng.randrange(len(data))
            data = data[:i] + bytes([rng.randrange(256)]) + data[i + 1:]
        elif choice == 1 and len(lines) > 1:               # delete a line
            del lines[rng.randrange(len(lines))]
            data = b"\n".join(lines)
        elif choice == 2:                                  # duplicate a line
            i = rng.randrange(len(lines))
            lines.insert(rng.randrange(len(lines) + 1), lines[i])
            data = b"\n".join(lines)
        elif choice == 3 and len(lines) > 1:               # swap two lines
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            data = b"\n".join(lines)
        elif choice == 4:                                  # a line from another case
            other = rng.choice(corpus).split(b"\n")
            lines.insert(rng.randrange(len(lines) + 1), rng.choice(other))
            data = b"\n".join(lines)
        elif choice == 5:                                  # insert a token anywhere
            i = rng.randrange(len(data) + 1)
            data = data[:i] + rng.choice(TOKENS).encode("utf-8", "surrogateescape") + data[i:]
        elif choice == 6:                                  # replace a value after ': '
            i = rng.randrange(len(lines))
            head, sep, _ = lines[i].partition(b": ")
            if sep:
                lines[i] = head + sep + rng.choice(TOKENS).encode()
                data = b"\n".join(lines)
        elif choice == 7 and data:                         # cut the file short
            data = data[:rng.randrange(len(data))]
        elif choice == 8:                                  # change the indentation of a line
            i = rng.randrange(len(lines))
            lines[i] = b" " * rng.choice((0, 1, 2, 4)) + lines[i].lstrip(b" ")
            data = b"\n".join(lines)
    return data


def run_one(data: bytes, path: str) -> tuple[str, str | None]:
    """("loaded" | "refused", None) if the loader kept its contract, else ("finding", what)."""
    with open(path, "wb") as stream:
        stream.write(data)
    signal.setitimer(signal.ITIMER_REAL, PER_INPUT_SECONDS)
    try:
        load_case(path)
        return "loaded", None
    except CaseError:
        return "refused", None
    except _Timeout:
        return "finding", f"hang: no answer within {PER_INPUT_SECONDS} s"
    except BaseException:  # noqa: BLE001 - anything else is a traceback for the user: a finding
        return "finding", traceback.format_exc()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)


def fuzz(seconds: float, seed: int, max_runs: int | None = None, artifacts: str | None = None,
         skipped: list | None = None) -> dict:
    """Mutate and load until `seconds` pass (or `max_runs` inputs); return the counts and findings."""
    rng = random.Random(seed)
    corpus = seeds(skipped=skipped)
    if not corpus:
        raise SystemExit(f"pd_fuzz_case_yaml: no seed case files under {ROOT}/cases")
    previous = signal.signal(signal.SIGALRM, _alarm)
    findings = []
    runs = loaded = 0
    start = time.monotonic()
    try:
        with tempfile.TemporaryDirectory(prefix="pd-fuzz-case-") as work:
            path = os.path.join(work, "case.yaml")
            while time.monotonic() - start < seconds and (max_runs is None or runs < max_runs):
                data = mutate(rng.choice(corpus), corpus, rng)
                outcome, finding = run_one(data, path)
                runs += 1
                loaded += outcome == "loaded"
                if finding is None:
                    continue
                findings.append((data, finding))
                if artifacts:
                    os.makedirs(artifacts, exist_ok=True)
                    with open(os.path.join(artifacts, f"pd_fuzz_case_yaml-{len(findings)}.yaml"), "wb") as out:
                        out.write(data)
    finally:
        signal.signal(signal.SIGALRM, previous)
    return {"runs": runs, "loaded": loaded, "seconds": time.monotonic() - start, "findings": findings}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pipeline.fuzz_case", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--seed", type=int, default=None, help="default: from the clock (printed)")
    parser.add_argument("--artifacts", default=None, help="folder for the inputs of findings")
    args = parser.parse_args(argv)
    seed = args.seed if args.seed is not None else int(time.time())
    limit_address_space(MEMORY_LIMIT_MB)  # a runaway input is a MemoryError (a finding), not the OOM killer
    skipped: list[str] = []
    result = fuzz(args.seconds, seed, artifacts=args.artifacts, skipped=skipped)
    for reason in skipped:
        print(f"pd_fuzz_case_yaml: seed skipped: {reason}", file=sys.stderr)
    print(f"pd_fuzz_case_yaml: seed {seed}: {result['runs']} inputs in {result['seconds']:.0f} s, "
          f"{result['loaded']} loaded, the rest refused with a CaseError; "
          f"{len(result['findings'])} finding(s)")
    for data, finding in result["findings"][:3]:
        print(f"--- input ({len(data)} bytes):\n{data[:400]!r}\n--- finding:\n{finding}", file=sys.stderr)
    return 1 if result["findings"] else 0


if __name__ == "__main__":
    sys.exit(main())
