"""A short, fixed-seed run of pdsolve's command-line fuzzer (pipeline/fuzz_cli.py; `make fuzz` runs it
for FUZZ_SECONDS): every argument list ends with a documented exit code, never a signal or an
internal error. The argument lists that once crashed are run every time."""
import subprocess

from pipeline.fuzz_cli import DOCUMENTED, fuzz, make_case


def test_random_command_lines_end_with_documented_codes(pdsolve):
    result = fuzz(pdsolve, seconds=120, seed=17, max_runs=25)
    assert result["runs"] == 25
    assert not result["findings"], result["findings"]
    assert set(result["codes"]) <= DOCUMENTED and len(result["codes"]) >= 2


def test_the_command_lines_that_crashed(pdsolve, tmp_path):
    case = make_case(str(tmp_path))
    for argv, code in (([case, "--threads", "100000"], 2), ([case, "--restart", "/dev/zero"], 1),
                       ([case, "--restart", str(tmp_path)], 1)):
        result = subprocess.run([pdsolve, *argv], capture_output=True, text=True, timeout=60, cwd=tmp_path)
        assert result.returncode == code, (argv, result.stderr)
        assert "internal error" not in result.stderr
