"""A copy of the repository's Makefile with its stages, in a temporary folder, for tests that run
the real `make case=X` on a short case of their own (signals, locks): cases/<name>/ is the test's,
the stages (common/, pipeline/, preprocess/, postprocess/) and the built solver are the repository's, by
symbolic link, and make is told not to rebuild the solver (SOLVER_SOURCES empty)."""
import os
import shutil
import signal
import subprocess
import time

import yaml

from e2e_support import ROOT, SOLVER


def make_tree(work, name="sig", end=10.0):
    """work/tree with cases/<name>/ a coarse membrane running `end` seconds of simulated time
    (10 s: it never finishes within a test) and its stages before the solve already run."""
    tree = work / "tree"
    (tree / "cases" / name).mkdir(parents=True)
    shutil.copy(os.path.join(ROOT, "Makefile"), tree / "Makefile")
    for folder in ("common", "pipeline", "preprocess", "postprocess"):
        os.symlink(os.path.join(ROOT, folder), tree / folder)
    (tree / "build").mkdir()
    os.symlink(os.path.dirname(SOLVER), tree / "build" / "solver")
    (tree / "build" / ".deps-ok").touch()
    shutil.copy(os.path.join(ROOT, "cases", "membrane", "membrane.geo"), tree / "cases" / name / f"{name}.geo")
    with open(os.path.join(ROOT, "cases", "membrane", "membrane.yaml"), encoding="utf-8") as stream:
        case = yaml.safe_load(stream)
    case["discretization"]["dx"] = 0.002
    case["node_sets"]["clamped"]["layer"] = 0.006
    case["time"]["end"] = end
    case["output"] = {"every_time": end / 50}
    (tree / "cases" / name / f"{name}.yaml").write_text(yaml.safe_dump(case))
    result = make(tree, name, f"out/{name}/case.json")
    assert result.returncode == 0, result.stdout + result.stderr
    return tree


def make_command(tree, name, *targets):
    return ["make", "--no-print-directory", "-C", str(tree), f"case={name}", "SOLVER_SOURCES=", *targets]


def make_env():
    return {k: v for k, v in os.environ.items() if k not in ("case", "config", "MAKEFLAGS", "MAKELEVEL", "MFLAGS")}


def make(tree, name, *targets, timeout=600):
    return subprocess.run(make_command(tree, name, *targets), env=make_env(), capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def default_sigint():
    """For preexec_fn: SIGINT at its default action in the child, whatever the runner's was.

    A shell started in the background (`cmd &` in a script, nohup) starts its children with SIGINT
    ignored; the solver keeps an inherited SIG_IGN on purpose (run/signals.cpp), so a test that
    stops it by SIGINT would then hang. Batch systems and terminals send SIGINT to processes that
    have it at its default: the tests set it so.
    """
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start_make(tree, name, *targets, prefix=(), env=None):
    """make in a session (and process group) of its own, as a CI job or a batch script runs it;
    env: variables added to make_env()'s."""
    return subprocess.Popen([*prefix, *make_command(tree, name, *targets)], env=dict(make_env(), **(env or {})),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL, start_new_session=True, preexec_fn=default_sigint)


def wait_for_steps(out, process, seconds=120):
    """Wait until the solver is stepping: history.csv has a row after its header."""
    deadline = time.monotonic() + seconds
    history = out / "history.csv"
    while time.monotonic() < deadline:
        assert process.poll() is None, process.communicate()
        if history.exists() and history.read_text().count("\n") >= 2:
            return
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    raise AssertionError("the solver did not start stepping")
