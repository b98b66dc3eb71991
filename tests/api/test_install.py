"""peridyn installs offline with Debian's pip and imports from any directory (issue 39, item 5):
before pyproject.toml, `import peridyn` failed outside the repository's root. The example of
docs/python-api.md's "Installing" section runs as it is, from a temporary directory."""
import os
import re
import subprocess
import sys

import pytest

from common.paths import pdsolve

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SOLVER = pdsolve()


def documented_example():
    text = open(os.path.join(ROOT, "docs", "python-api.md"), encoding="utf-8").read()
    match = re.search(r"<!-- example: tests/api/test_install.py.*?-->\n```python\n(.*?)```", text, re.S)
    assert match, "docs/python-api.md lost its tested example"
    return match.group(1)


def test_an_editable_install_imports_from_anywhere_and_runs_the_documented_example(tmp_path):
    if not os.path.isfile(SOLVER):
        pytest.fail(f"{SOLVER} is missing: build it with `make solver`")
    prefix = tmp_path / "prefix"
    # As the README's line, but into a prefix of the test's own (not the user's site-packages).
    install = subprocess.run([sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps",
                              "--break-system-packages", "--no-index", "--prefix", str(prefix), "-e", ROOT],
                             capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert install.returncode == 0, install.stdout + install.stderr
    assert not os.path.exists(os.path.join(ROOT, "peridyn.egg-info"))     # nothing left in the checkout
    site_dirs = {os.path.dirname(p) for p in map(str, prefix.rglob("*.pth"))}
    assert len(site_dirs) == 1, site_dirs
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PDSOLVE"] = SOLVER
    # Without the install, the import fails from here: the test would not tell the two apart.
    bare = subprocess.run([sys.executable, "-c", "import peridyn"], cwd=work, env=env, capture_output=True, text=True)
    assert bare.returncode != 0 and "No module named 'peridyn'" in bare.stderr
    script = f"import site; site.addsitedir({site_dirs.pop()!r})\n" + documented_example()
    result = subprocess.run([sys.executable, "-c", script], cwd=work, env=env, capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
    assert re.search(r"^5 frames; largest \|u_z\|: [0-9.e-]+ m$", result.stdout, re.M), result.stdout
    assert (work / "membrane-coarse" / "history.csv").exists()
