"""Mutation fuzzing of the Python readers (UNV mesh, node file): thousands of seeded mutants of valid
files must each give a result or a PreprocessError, never another exception and never a hang.

Seeded and bounded (a few thousand mutants, a few seconds each reader), so a failure reproduces:
the message carries the seed and the mutant is saved next to the test's temporary files.
"""
import random
import signal
import warnings

import numpy as np
import pytest

from preprocess import NodeCloud, PreprocessError
from preprocess.node_file import read_node_file, write_node_file
from preprocess.readers import read_mesh

MUTANTS = 2500
SECONDS_PER_CALL = 5  # a reader that needs longer on a file of a few kB hangs

# Nodes, a beam, triangles, a quad, a quadratic element, node and element groups, an unknown dataset.
UNV = """\
    -1
   164
        1SI: Meter (newton)         2
  1.0000000000000000D+00  1.0000000000000000D+00  1.0000000000000000D+00
  2.7314999999999998D+02
    -1
    -1
  2411
         1         1         1        11
   0.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00
         2         1         1        11
   1.0000000000000000D+00   0.0000000000000000D+00   0.0000000000000000D+00
         3         1         1        11
   1.0000000000000000D+00   1.0000000000000000D+00   0.0000000000000000D+00
         4         1         1        11
   0.0000000000000000D+00   1.0000000000000000D+00   0.0000000000000000D+00
         5         1         1        11
   5.0000000000000000D-01   5.0000000000000000E-01   0.0000000000000000D+00
    -1
    -1
  2412
         1        21         1         1         7         2
         0         0         0
         1         2
         2        41         1         1         7         3
         1         2         5
         3        41         1         1         7         3
         2         3         5
         4        44         1         1         7         4
         1         5         3         4
         5        24         1         1         7         3
         0         0         0
         1         5         3
    -1
    -1
  2467
         1         0         0         0         0         0         0         4
plate
         8         2         0         0         8         3         0         0
         8         4         0         0         8         1         0         0
         2         0         0         0         0         0         0         2
left
         7         1         0         0         7         4         0         0
    -1
"""


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang()


def mutate(data: bytes, rng: random.Random) -> bytes:
    """One to four random edits of the kinds that hand editing, truncation and bit rot produce."""
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(9)
        i = rng.randrange(len(b) + 1)
        j = min(len(b), i + rng.randint(1, 64))
        if op == 0 and b:                                   # flip a bit
            k = rng.randrange(len(b))
            b[k] ^= 1 << rng.randrange(8)
        elif op == 1:                                       # random bytes
            b[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif op == 2:                                       # delete a range
            del b[i:j]
        elif op == 3:                                       # duplicate a range
            b[i:i] = b[i:j]
        elif op == 4:                                       # truncate
            del b[i:]
        elif op == 5:                                       # a number token becomes an extreme one
            token = rng.choice([b"-1", b"0", b"99999999999999999999999", b"-7", b"nan", b"inf", b"1e308",
                                b"1D+999", b"2147483648", b"18446744073709551616"])
            b[i:j] = token
        elif op == 6:                                       # copy a line elsewhere
            lines = bytes(b).split(b"\n")
            if len(lines) > 1:
                lines.insert(rng.randrange(len(lines)), rng.choice(lines))
                b = bytearray(b"\n".join(lines))
        elif op == 7:                                       # drop a line
            lines = bytes(b).split(b"\n")
            if len(lines) > 1:
                del lines[rng.randrange(len(lines))]
                b = bytearray(b"\n".join(lines))
        else:                                               # a digit changes
            digits = [k for k, c in enumerate(b) if 48 <= c <= 57]
            if digits:
                b[rng.choice(digits)] = rng.randrange(48, 58)
    return bytes(b)


def fuzz(reader, seed_bytes: bytes, path, seed: int):
    rng = random.Random(seed)
    outcomes = {"ok": 0, "error": 0}
    previous = signal.signal(signal.SIGALRM, _alarm)
    try:
        for k in range(MUTANTS):
            mutant = mutate(seed_bytes, rng)
            path.write_bytes(mutant)
            signal.alarm(SECONDS_PER_CALL)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    reader(str(path))
                outcomes["ok"] += 1
            except PreprocessError as err:
                assert str(err).startswith(str(path)), f"mutant {k} (seed {seed}): message lacks the file: {err}"
                outcomes["error"] += 1
            except Hang:
                kept = path.with_suffix(f".hang{k}{path.suffix}")
                kept.write_bytes(mutant)
                pytest.fail(f"mutant {k} (seed {seed}) hangs the reader; kept in {kept}")
            except Exception as err:  # noqa: BLE001 - the point of the test
                kept = path.with_suffix(f".crash{k}{path.suffix}")
                kept.write_bytes(mutant)
                pytest.fail(f"mutant {k} (seed {seed}): {type(err).__name__}: {err}; kept in {kept}")
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    return outcomes


def test_seed_files_are_valid(tmp_path):
    path = tmp_path / "seed.unv"
    path.write_text(UNV)
    mesh = read_mesh(str(path))
    assert len(mesh.points) == 5 and set(mesh.groups) == {"plate", "left"}


def test_unv_reader_survives_mutants(tmp_path):
    # Seed 2 reached an OverflowError (a 23-digit node label) at its 8th mutant before unv.py bounded labels.
    outcomes = fuzz(read_mesh, UNV.encode(), tmp_path / "mutant.unv", seed=2)
    # Both outcomes occur: the mutations are neither all fatal nor all harmless.
    assert outcomes["error"] > MUTANTS // 10 and outcomes["ok"] > 10, outcomes


def test_huge_unv_label_is_a_clear_error(tmp_path):
    path = tmp_path / "huge.unv"
    path.write_text(UNV.replace("         5         1         1        11",
                                "99999999999999999999999         1         1        11"))
    with pytest.raises(PreprocessError, match=rf"^{path}:17: bad record .* too large for a label"):
        read_mesh(str(path))


def test_node_file_reader_survives_mutants(tmp_path):
    n = 6
    cloud = NodeCloud(points=np.array([[i * 0.1, (i % 2) * 0.1, 0.0] for i in range(n)]),
                      volume=np.full(n, 1e-5), block=np.array([1, 1, 1, 2, 2, 2], np.int32),
                      sets={"left": np.array([1, 0, 1, 0, 0, 0], bool)}, grid_spacing=0.1, dimension=2)
    seed = tmp_path / "seed.vtu"
    write_node_file(str(seed), cloud)
    assert len(read_node_file(str(seed)).volume) == n
    outcomes = fuzz(read_node_file, seed.read_bytes(), tmp_path / "mutant.vtu", seed=7)
    assert outcomes["error"] > MUTANTS // 10 and outcomes["ok"] > 10, outcomes
