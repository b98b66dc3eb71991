"""bench/explicit_reuse.py: when an explicit run of an earlier benchmark folder stands for this
run's (--reuse-explicit: same inputs and same solver file; --explicit-from: same inputs, the first
run of a problem rerun and compared), on a fake solver (a Python script writing run.log, history.csv
and a frame, counting its calls); under a second."""
import json
import os
import stat

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from bench import quasi_static_cases as qs  # noqa: E402
from bench.explicit_reuse import RECORD, ExplicitSource, result_digests  # noqa: E402

# The fake solver: the result (history's last column, the frame's text) is the solver file's
# RESULT constant, so that two copies differing in it play two solvers that disagree.
FAKE = """#!/usr/bin/python3
import os, sys
RESULT = "{result}"
run_dir = os.path.dirname(os.path.abspath(sys.argv[1]))
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "calls"), "a") as f:
    f.write(run_dir + "\\n")
os.makedirs(os.path.join(run_dir, "frames"), exist_ok=True)
with open(os.path.join(run_dir, "run.log"), "w") as f:
    f.write("done: 10 steps to t = 0.001 s in 0.5 s wall (1e+08 bond updates/s), 1 frames, 7 broken bonds, "
            "11 force evaluations\\n")
with open(os.path.join(run_dir, "history.csv"), "w") as f:
    f.write("step,time,wall_time,x\\n0,0,0.{wall},1\\n10,0.001,0.5,%s\\n" % RESULT)
with open(os.path.join(run_dir, "frames.pvd"), "w") as f:
    f.write("<pvd/>\\n")
with open(os.path.join(run_dir, "frames", "frame_000000.vtu"), "w") as f:
    f.write(RESULT + "\\n")
"""


def fake_solver(folder, result="2", wall="1", tag=""):
    """A fake solver file in `folder`; `wall` changes only the history's wall_time column, `tag`
    only the file's bytes (a comment): another solver giving the same results."""
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "pdsolve")
    with open(path, "w") as stream:
        stream.write(FAKE.format(result=result, wall=wall) + f"# {tag}\n")
    os.chmod(path, os.stat(path).st_mode | stat.S_IEXEC)
    return path


def calls(solver):
    try:
        with open(os.path.join(os.path.dirname(solver), "calls")) as stream:
            return len(stream.read().splitlines())
    except OSError:
        return 0


def bench_folder(out, runs=("verlet-alpha10-v0.5", "verlet-alpha10-v0.25"), nodes=b"lattice", speed=0.5):
    """out/traction/nodes.vtu and a case.json per run, as quasi_static_cases.write lays them out."""
    os.makedirs(os.path.join(out, "traction"), exist_ok=True)
    with open(os.path.join(out, "traction", "nodes.vtu"), "wb") as stream:
        stream.write(nodes)
    return [qs.write(os.path.join(out, "traction"), name, {"speed": speed, "nodes_file": "../nodes.vtu"})
            for name in runs]


def run_all(source, paths):
    return [source.run("traction", path, qs.timed_run) for path in paths]


def test_reuse_explicit_takes_a_run_only_with_identical_inputs_and_the_same_solver_file(tmp_path):
    solver = fake_solver(tmp_path / "a")
    old = bench_folder(str(tmp_path / "old"))
    first = run_all(ExplicitSource(None, "reuse", solver, 1), old)
    assert calls(solver) == 2
    record = json.load(open(os.path.join(os.path.dirname(old[0]), RECORD)))
    assert record["threads"] == 1 and record["steps"] == 10 and record["evaluations"] == 11
    assert record["cpu"] == first[0][0]["cpu"] and len(record["solver_sha256"]) == 64

    new = bench_folder(str(tmp_path / "new"))
    source = ExplicitSource(str(tmp_path / "old"), "reuse", solver, 1)
    got = run_all(source, new)
    assert calls(solver) == 2                                   # nothing ran
    for (r, run_dir, note), (r0, run_dir0, _) in zip(got, first):
        assert run_dir == run_dir0 and note == f"reused from {run_dir0}"
        assert (r["steps"], r["evaluations"], r["broken_bonds"], r["cpu"]) == (10, 11, 7, r0["cpu"])
    assert source.summary().startswith("explicit runs: 2 taken from")

    # Each difference runs it here, and says why.
    changed = bench_folder(str(tmp_path / "changed"), speed=0.25)
    r, run_dir, note = ExplicitSource(str(tmp_path / "old"), "reuse", solver, 1).run("traction", changed[0], qs.timed_run)
    assert calls(solver) == 3 and run_dir == os.path.dirname(changed[0]) and "case.json differs" in note
    relaid = bench_folder(str(tmp_path / "relaid"), nodes=b"another lattice")
    assert "nodes.vtu differs" in ExplicitSource(str(tmp_path / "old"), "reuse", solver, 1).run(
        "traction", relaid[0], qs.timed_run)[2]
    threads = bench_folder(str(tmp_path / "threads"))
    assert "on 1 thread(s)" in ExplicitSource(str(tmp_path / "old"), "reuse", solver, 2).run(
        "traction", threads[0], qs.timed_run)[2]
    other = fake_solver(tmp_path / "b", tag="rebuilt")          # same results, another file
    again = bench_folder(str(tmp_path / "again"))
    assert "another solver made it" in ExplicitSource(str(tmp_path / "old"), "reuse", other, 1).run(
        "traction", again[0], qs.timed_run)[2]
    assert calls(other) == 1


def test_explicit_from_reruns_the_first_run_compares_it_and_takes_the_rest(tmp_path):
    solver = fake_solver(tmp_path / "a")
    run_all(ExplicitSource(None, "reuse", solver, 1), bench_folder(str(tmp_path / "old")))
    other = fake_solver(tmp_path / "b", wall="7", tag="the mixed change")   # same results but wall_time
    new = bench_folder(str(tmp_path / "new"))
    source = ExplicitSource(str(tmp_path / "old"), "from", other, 1)
    (r1, dir1, note1), (r2, dir2, note2) = run_all(source, new)
    assert calls(other) == 1                                    # the first, checked; the second taken
    assert dir1 == os.path.dirname(new[0]) and note1.startswith("run here, the same results as")
    assert dir2 == str(tmp_path / "old" / "traction" / "verlet-alpha10-v0.25") and note2.startswith("reused from")
    assert result_digests(dir1) == result_digests(str(tmp_path / "old" / "traction" / "verlet-alpha10-v0.5"))

    wrong = fake_solver(tmp_path / "c", result="3")             # a solver whose explicit runs differ
    with pytest.raises(SystemExit, match=r"frames/frame_000000.vtu, history.csv differ"):
        run_all(ExplicitSource(str(tmp_path / "old"), "from", wrong, 1), bench_folder(str(tmp_path / "new2")))


def test_explicit_from_reads_the_cpu_time_of_a_run_without_record_from_accuracy_csv(tmp_path):
    solver = fake_solver(tmp_path / "a")
    old = bench_folder(str(tmp_path / "old"))
    run_all(ExplicitSource(None, "reuse", solver, 1), old)
    for path in old:
        os.remove(os.path.join(os.path.dirname(path), RECORD))    # as a run made before the records
    with open(tmp_path / "old" / "accuracy.csv", "w") as stream:
        stream.write("problem,scheme,parameter,wall_time,cpu_time,status,run_dir\n")
        for path, cpu in zip(old, (0.25, 0.75)):
            stream.write(f"traction,verlet-alpha10,0.5,0.5,{cpu},ok,{os.path.dirname(path)}\n")
    # --reuse-explicit cannot know the solver: runs here.
    assert "no bench_run.json there" in ExplicitSource(str(tmp_path / "old"), "reuse", solver, 1).run(
        "traction", bench_folder(str(tmp_path / "strict"))[0], qs.timed_run)[2]
    got = run_all(ExplicitSource(str(tmp_path / "old"), "from", solver, 1), bench_folder(str(tmp_path / "new")))
    assert got[1][0]["cpu"] == 0.75 and got[1][2].startswith("reused from")


def test_the_reuse_options_refuse_a_missing_folder_and_the_output_folder(tmp_path):
    import argparse
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out")
    qs.add_arguments(parser)
    for argv, message in ((["--reuse-explicit", str(tmp_path / "none")], "no such folder"),
                          (["--explicit-from", str(tmp_path)], "the same folder as --out")):
        args = parser.parse_args(argv + ["--out", str(tmp_path)])
        with pytest.raises(SystemExit, match=message):
            qs.settle_arguments(args)
    with pytest.raises(SystemExit):
        parser.parse_args(["--reuse-explicit", "a", "--explicit-from", "b"])


def test_case_json_compared_byte_for_byte_but_its_source_line(tmp_path):
    from bench.explicit_reuse import case_sha256
    cases = []
    for name, source, speed in (("a", "/work/one/cases/traction/mixed.yaml", 0.5),
                                ("b", "/work/two/cases/traction/mixed.yaml", 0.5), ("c", "/work/one/x.yaml", 0.25)):
        cases.append(qs.write(str(tmp_path / name), "run", {"source": source, "speed": speed}))
    assert case_sha256(cases[0]) == case_sha256(cases[1])      # another checkout: the same case
    assert case_sha256(cases[0]) != case_sha256(cases[2])      # another speed


def test_a_verlet_case_is_compared_without_the_load_steps_it_never_reads(tmp_path):
    # mixed.yaml's quasi_static block rides along in the explicit cases: a Verlet run's hash leaves it
    # out, a mixed run's does not; anything else still counts.
    from bench.explicit_reuse import case_sha256

    def case(name, integrator, dt_max, speed=0.5):
        return qs.write(str(tmp_path / name), "run", {"time": {"integrator": integrator, "end": 1.0},
                                                       "quasi_static": {"dt_initial": dt_max, "dt_max": dt_max},
                                                       "speed": speed})
    assert case_sha256(case("a", "verlet", 1e-4)) == case_sha256(case("b", "verlet", 1e-3))
    assert case_sha256(case("c", "verlet", 1e-4)) != case_sha256(case("d", "verlet", 1e-4, 0.25))
    assert case_sha256(case("e", "mixed", 1e-4)) != case_sha256(case("f", "mixed", 1e-3))


def test_results_compare_without_the_energy_sums_but_with_every_column_the_benchmark_reads(tmp_path):
    # Two runs whose histories differ only in an energy sum's last digit (as after the exact sums
    # of 3 Dec 2026) have the same digests; a reaction that differs does not.
    header = "step,time,kinetic_energy,strain_energy,wall_time,broken_bonds,reaction_right_fx\n"
    rows = {"a": "1,0.1,1.0000000000000002,3.0,0.5,0,12.5\n",
            "b": "1,0.1,1.0000000000000004,3.0,0.7,0,12.5\n",
            "c": "1,0.1,1.0000000000000002,3.0,0.5,0,12.500000000000002\n"}
    digests = {}
    for name, row in rows.items():
        run = tmp_path / name
        run.mkdir()
        (run / "history.csv").write_text(header + row)
        digests[name] = result_digests(str(run))
    assert digests["a"] == digests["b"]
    assert digests["a"] != digests["c"]
