"""The case-file loader is safe and bounded (issue 17, item 3): hostile or mistaken files end in one
clean error naming the file and line, quickly, never a Python traceback or a hang.

Each file goes through the real entry point, `python3 -m pipeline.run check` (what `make check` and
every stage run), under a time limit: before the bounded loader, the alias bomb ran for minutes and
the others ended in tracebacks.
"""
import os
import subprocess
import sys
import time

import pytest

from pipeline.case import CaseError, load_case

from minimal_case import MINIMAL

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))



def check(path, timeout=30):
    """Run `pipeline.run check` on the file; return (exit code, stderr, seconds)."""
    start = time.monotonic()
    result = subprocess.run([sys.executable, "-m", "pipeline.run", "check", str(path)], cwd=ROOT,
                            capture_output=True, text=True, timeout=timeout)
    return result.returncode, result.stderr, time.monotonic() - start


def billion_laughs(levels=10):
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]")
    return "\n".join(lines) + "\n"


HOSTILE = {
    # name: (file content, expected text in the error, expected line)
    "python_tag": (MINIMAL + "damping: !!python/object:builtins.float 1.0\n",
                   "the tag 'tag:yaml.org,2002:python/object:builtins.float' is not allowed", 11),
    "custom_tag": (MINIMAL + "damping: !foo 1.0\n", "the tag '!foo' is not allowed", 11),
    "tagged_section": (MINIMAL.replace("time:", "time: !!map"), "the tag 'tag:yaml.org,2002:map'", 9),
    "merge_key": (MINIMAL + "base: &b {end: 1.0}\nother:\n  <<: *b\n", "merge keys ('<<') are not supported", 13),
    "recursive_anchor": (MINIMAL + "title: &x [1, *x]\n", "a value that contains it (a cycle)", 11),
    "billion_laughs": (billion_laughs(), "more than 100000 values once aliases (*name) are expanded", None),
    "deep_brackets": ("title: " + "[" * 50_000 + "]" * 50_000 + "\n", "nested more than 64 levels deep", 1),
    "sexagesimal": (MINIMAL + "damping: 5:00\n", "'5:00' is a base-60 number in YAML 1.1", 11),
    "octal_11": (MINIMAL + "damping: 012\n", "'012' starts with 0", 11),
    "underscore": (MINIMAL + "damping: 1_000\n",
                   "damping: expected a number [1/s], got '1_000' (YAML 1.2 reads this as text", 11),
    "long_line_title": (MINIMAL + "title: " + "x" * 300 + "\n",
                        "title: expected one line of at most 200 characters, got 300 characters", 11),
    "long_value": (MINIMAL + "title: " + "x" * 20_000 + "\n", "a value of 20000 characters", 11),
    "two_documents": (MINIMAL + "---\n" + MINIMAL, "not valid YAML: expected a single document in the stream, but found another document", 11),
    # Whole numbers past a double (issue 36, item 11): an OverflowError from float() (400 digits)
    # and Python's int-string limit (5000 digits > 4300) were tracebacks before.
    "int_400_digits": (MINIMAL + "damping: 1" + "0" * 400 + "\n",
                       "damping: the whole number 100000000000…000000 (401 characters) is too large", 11),
    "int_5000_digits": (MINIMAL.replace("  end: 1.0e-3\n", "  end: 1.0e-3\n  max_steps: 1" + "0" * 5000 + "\n"),
                        "time.max_steps: the whole number 100000000000…000000 (5001 characters) is too large", 11),
    "hex_past_a_double": (MINIMAL + "damping: 0x" + "f" * 300 + "\n", "damping: the whole number 0xffffffffff", 11),
    "int_key_400_digits": (MINIMAL + "geometry:\n  parameters:\n    1" + "0" * 400 + ": 1\n",
                           "geometry.parameters: the whole number", 13),
}


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_yaml_is_one_clean_error_with_the_line(tmp_path, name):
    text, expected, line = HOSTILE[name]
    path = tmp_path / "plate.yaml"
    path.write_text(text)
    code, err, seconds = check(path)
    assert "Traceback" not in err, err[-2000:]
    assert code == 2, err[-2000:]
    assert err.startswith(f"error: {path}:{line or ''}"), err[:400]
    assert expected in err, err[:400]
    assert seconds < 20


def test_binary_file_is_refused(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_bytes(b"dimension: 2\n" + bytes(range(256)) * 4)
    code, err, _ = check(path)
    assert code == 2 and "Traceback" not in err
    assert f"error: {path}:2: a NUL byte: this is a binary file, not a case file" in err


def test_latin1_file_is_refused_with_the_line(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_bytes(MINIMAL.encode() + "title: Pr\u00fcfk\u00f6rper\n".encode("latin-1"))
    with pytest.raises(CaseError, match=r"plate\.yaml:11: not UTF-8 text \(byte 0xfc\)"):
        load_case(str(path))


def test_two_megabyte_title_is_refused_before_parsing(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL + "title: " + "x" * (2 << 20) + "\n")
    code, err, _ = check(path)
    assert code == 2 and "Traceback" not in err
    assert f"error: {path}: larger than 1024 kB" in err


@pytest.mark.parametrize("target", ["directory", "/dev/zero"])
def test_a_directory_or_device_is_not_a_case_file(tmp_path, target):
    path = str(tmp_path) if target == "directory" else target
    with pytest.raises(CaseError) as info:
        load_case(path)
    assert str(info.value).startswith(f"{path}: ")
    assert ("not a regular file" in str(info.value)) or ("cannot read" in str(info.value))


def test_a_fifo_is_refused_at_once_not_waited_on(tmp_path):
    """A FIFO as the case file hung `make check` in open() (issue 36, item 11): now refused without
    blocking, by check and by peridyn.load (a writer never comes, so a hang would hit the timeout)."""
    path = tmp_path / "plate.yaml"
    os.mkfifo(path)
    code, err, seconds = check(path, timeout=20)
    assert code == 2 and "Traceback" not in err, err
    assert err == f"error: {path}: a FIFO (named pipe), not a regular file; a case input must be a regular file in {tmp_path}\n"
    import peridyn
    with pytest.raises(CaseError, match="plate.yaml: a FIFO"):
        peridyn.load(str(path))


def test_a_fifo_as_the_given_mesh_is_refused(tmp_path):
    """`check CASE MESH` with a FIFO as the given mesh: refused, not read (it would block too)."""
    case, mesh = tmp_path / "plate.yaml", tmp_path / "plate.msh"
    case.write_text(MINIMAL)
    os.mkfifo(mesh)
    result = subprocess.run([sys.executable, "-m", "pipeline.run", "check", str(case), str(mesh)], cwd=ROOT,
                            capture_output=True, text=True, timeout=20)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert f"error: {mesh}: a FIFO (named pipe), not a regular file" in result.stderr


def test_a_fifo_in_place_of_the_mesh_parameters_is_replaced_not_read(tmp_path):
    """The mesh-parameters stage reads its old output to leave it unchanged: a FIFO there blocked."""
    case, out = tmp_path / "plate.yaml", tmp_path / "mesh-parameters.json"
    case.write_text(MINIMAL + "geometry:\n  parameters: {L: 0.05}\n")
    os.mkfifo(out)
    result = subprocess.run([sys.executable, "-m", "pipeline.run", "mesh-parameters", str(case), str(out)], cwd=ROOT,
                            capture_output=True, text=True, timeout=20)
    assert result.returncode == 0, result.stderr
    assert out.read_text() == '{\n "L": 0.05\n}\n'


def test_huge_whole_numbers_are_refused_by_the_api_loader_too(tmp_path):
    """peridyn.load read the file with yaml.safe_load after the check: the same 5000-digit value
    is one CaseError at its line there too, and validate() given such an int by a program says so."""
    import peridyn
    from pipeline.validate import validate
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL + "damping: 1" + "0" * 5000 + "\n")
    with pytest.raises(CaseError, match=r"plate\.yaml:11: damping: the whole number .* is too large"):
        peridyn.load(str(path))
    with pytest.raises(CaseError, match=r"x\.yaml:1: damping: a whole number of about 10\^5000 is too large"):
        validate({"damping": 10 ** 5000}, "x.yaml", {})


def test_yaml_12_core_schema(tmp_path):
    """`yes`, `on` and dates are text in YAML 1.2; 1e-3, 0x10, 0o17 and .inf are numbers."""
    from pipeline.yaml_lines import load_with_lines
    path = tmp_path / "values.yaml"
    path.write_text("a: yes\nb: on\nc: 2001-12-14\nd: 1e-3\ne: 0x10\nf: 0o17\ng: -.inf\nh: ~\n"
                    "i: TRUE\nj: '5:00'\nk: 12\n")
    data, lines = load_with_lines(str(path))
    assert data == {"a": "yes", "b": "on", "c": "2001-12-14", "d": 1e-3, "e": 16, "f": 15,
                    "g": float("-inf"), "h": None, "i": True, "j": "5:00", "k": 12}
    assert isinstance(data["d"], float) and isinstance(data["k"], int)
    assert lines[("g",)] == 7


def test_anchors_and_aliases_of_whole_values_still_work(tmp_path):
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL.replace("    youngs_modulus: 1.0e9\n",
                                    "    youngs_modulus: 1.0e9\n  ring: *steel\n")
                    .replace("  plate:\n", "  plate: &steel\n"))
    case = load_case(str(path))
    assert case["materials"]["ring"] == case["materials"]["plate"]
    assert case["materials"]["ring"]["youngs_modulus"] == 1.0e9


def test_a_control_character_names_its_line(tmp_path):
    """Found by pipeline/fuzz_case.py: PyYAML's reader refuses control characters in its constructor."""
    path = tmp_path / "plate.yaml"
    path.write_text(MINIMAL.replace("time:", "ti\x0bme:"))
    with pytest.raises(CaseError, match=r"plate\.yaml:9: character #x000b is not allowed in YAML text"):
        load_case(str(path))
