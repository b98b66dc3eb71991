"""The marker shared by every test folder.

`slow`: an end-to-end run whose assertions other tests already make in part (on a smaller model, or
one stage at a time). `make test` deselects it (`-m 'not slow'`) to stay near 20 minutes on two
cores; `make validate` runs it (`-m slow`), so nothing stops being checked. A plain `pytest tests`
runs everything.
"""


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "slow: an end-to-end run that make validate runs and make test deselects (tests/conftest.py)")
