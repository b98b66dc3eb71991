"""docs/quick-start.md runs as written: its .geo and .yaml blocks make a case that checks, solves
and breaks, and the error messages it shows are the ones the pipeline prints for those mistakes."""
import csv
import os
import re
import subprocess

import pytest

from e2e_support import PY, ROOT, SOLVER, new_case_folder, prepare_stages

DOC = os.path.join(ROOT, "docs", "quick-start.md")


def blocks(kind):
    text = open(DOC, encoding="utf-8").read()
    return re.findall(rf"```{kind}\n(.*?)```", text, flags=re.S)


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    work, case_dir = new_case_folder(tmp_path_factory, "quick_start", "bar")
    (geo,), (yaml,) = blocks("geo"), blocks("yaml")
    (case_dir / "bar.geo").write_text(geo)
    (case_dir / "bar.yaml").write_text(yaml)
    return work, case_dir, yaml


def check(work, yaml_text):
    (work / "cases" / "bar" / "bar.yaml").write_text(yaml_text)
    result = subprocess.run([PY, "-m", "pipeline.run", "check", "cases/bar/bar.yaml"], cwd=work,
                            env=dict(os.environ, PYTHONPATH=ROOT), capture_output=True, text=True, timeout=300)
    return result.returncode, result.stdout + result.stderr.replace(str(work) + os.sep, "")


def test_the_case_checks(case):
    work, _, yaml = case
    code, output = check(work, yaml)
    assert code == 0 and "cases/bar/bar.yaml: ok (2D plane_stress, 1 block(s), end time 0.0006 s;" in output


def test_the_mistakes_give_the_messages_the_page_shows(case):
    work, _, yaml = case
    misspelt_key, misspelt_set = blocks("text")
    right_grip = "  - set: right\n    velocity: {x: [[0.0, 0.0], [1.0e-4, 0.5]]}\n"
    assert right_grip in yaml
    code, output = check(work, yaml.replace(right_grip, right_grip.replace("velocity", "velocty")))
    assert code != 0 and misspelt_key.strip() in output
    code, output = check(work, yaml.replace("  - set: right\n", "  - set: rigth\n"))
    assert code != 0 and misspelt_set.strip() in output
    check(work, yaml)


def test_the_notched_bar_breaks_across_its_width(case):
    work, case_dir, _ = case
    out = work / "out" / "bar"
    out.mkdir(parents=True)
    prepare_stages(case_dir / "bar.yaml", case_dir / "bar.geo", out)
    result = subprocess.run([SOLVER, str(out / "case.json"), "--quiet"], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    with open(out / "history.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert float(rows[-1]["time"]) == pytest.approx(6.0e-4)
    # The notch's bonds are broken from the start (8 node rows); the crack then runs through the
    # remaining 16 mm, 32 more rows at dx 0.5 mm, each cut across some 17 bonds (δ = 3 dx): hundreds.
    notch = int(rows[0]["broken_bonds"])
    assert 0 < notch < 300 and int(rows[-1]["broken_bonds"]) - notch > 400
    # The right grip is pulled, then let go by the crack: its reaction rises and falls back.
    force = [float(r["reaction_right_fx"]) for r in rows]
    assert max(force) > 0 and abs(force[-1]) < 0.2 * max(force)
