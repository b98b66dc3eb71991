"""Fixtures of the pipeline tests that ask the built solver (pdsolve --describe, --stable-dt)."""
import os

import pytest

from common import paths

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture(scope="session")
def pdsolve():
    """The solver's path (PDSOLVE overrides, as in tests/e2e); fails at once if it is not built."""
    path = paths.pdsolve()
    if not os.path.exists(path):
        pytest.fail(f"{path} is missing: build it with `make solver` (make test does)")
    return path
