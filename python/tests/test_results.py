"""Results that feel like Python (issue 32 item 4): result objects with attributes, a short
repr and to_dict(); numpydoc on every public function; sweeps from an in-memory grid;
diagnose with the CLI's metric, no_refit and screen_samples."""
import inspect
import json
import re

import numpy as np
import pytest

import moreau

from conftest import WORKED
from test_commands import BAM_DATA, BAM_MODEL


def test_theta_is_a_result_object_and_still_the_cli_dict(cli):
    r = moreau.theta(WORKED, measure=False)
    assert isinstance(r, moreau.ThetaResult) and isinstance(r, dict)
    assert r.theta_best == r["theta_best"] and r.theta_verified is r["theta_verified"]
    ref = json.loads(cli.run("theta", WORKED, "--json", "--no-measure").stdout)
    assert r.to_dict() == ref and type(r.to_dict()) is dict
    text = repr(r)
    assert text.startswith("ThetaResult(") and f"theta_best={r.theta_best:.4g}" in text and len(text) < 300, text
    with pytest.raises(AttributeError, match="no key or attribute 'thetta'"):
        r.thetta
    assert "theta_best" in dir(r)


def test_periodic_and_trajectory_read_as_attributes():
    p = moreau.periodic(WORKED, periods=20, pairs=1)
    assert isinstance(p, moreau.PeriodicResult) and p.rate["exponent"] < 0
    assert repr(p).startswith("PeriodicResult(")
    tr = moreau.simulate(WORKED, periods=2)
    assert tr.y is tr["y"] and tr.t.shape == (len(tr["t"]),)
    assert repr(tr).startswith("Trajectory(") and "samples" in repr(tr)
    assert set(tr.to_dict()) == {"t", "w", "x", "y", "z", "q"}


def _public_functions():
    """Every public function of the package and every public method of System."""
    out = []
    for name in moreau.__all__:
        obj = getattr(moreau, name)
        if inspect.isfunction(obj):
            out.append((name, obj))
    for name, member in vars(moreau.System).items():
        if name.startswith("_"):
            continue
        fn = member.__func__ if isinstance(member, (classmethod, staticmethod)) else member
        if inspect.isfunction(fn):
            out.append((f"System.{name}", fn))
    return out


def _numpydoc_problems(name, fn):
    doc = inspect.getdoc(fn) or ""
    problems = []
    takes = [p for p in inspect.signature(fn).parameters if p not in ("self", "cls")]
    if takes and not re.search(r"^Parameters\n-{10}$", doc, re.M):
        problems.append(f"{name}: no 'Parameters' section")
    if not re.search(r"^Returns\n-{7}$", doc, re.M):
        problems.append(f"{name}: no 'Returns' section")
    section = re.search(r"^Parameters\n-{10}\n(.*?)(?:\n\n\S[^\n]*\n-{3,}\n|\Z)", doc, re.M | re.S)
    entries = set()
    for line in (section.group(1) if section else "").splitlines():
        if line and not line[0].isspace():
            entries |= {n.strip().lstrip("*") for n in line.split(":")[0].split(",")}
    for p in takes:
        if p not in entries:
            problems.append(f"{name}: parameter {p} not documented")
    return problems


def test_every_public_function_has_numpydoc_parameters_and_returns():
    fns = _public_functions()
    assert len(fns) >= 14, [n for n, _ in fns]
    problems = [p for name, fn in fns for p in _numpydoc_problems(name, fn)]
    assert not problems, "\n".join(problems)


def test_the_numpydoc_check_rejects_a_bare_docstring():
    def bare(x, y=1):
        """Does something with x."""

    assert len(_numpydoc_problems("bare", bare)) == 4


def test_a_sweep_from_an_in_memory_grid_is_the_spec_files_sweep(tmp_path):
    r = moreau.sweep_grid(WORKED, {"input.amplitude": np.array([1.0, 5.0])}, tmp_path / "grid", evaluate={"measure": False})
    assert isinstance(r, moreau.SweepResult) and r.complete
    assert list(r.table["input.amplitude"]) == [1.0, 5.0]
    assert r.table["theta"][0] == pytest.approx(-0.0172, abs=1e-3)
    assert "2 points" in repr(r) and "0 failed" in repr(r)
    spec = tmp_path / "grid" / "spec" / "spec.toml"
    assert spec.exists(), "the spec written is kept beside the tables"
    again = moreau.sweep(spec, tmp_path / "again")
    assert again.table["theta"].tolist() == r.table["theta"].tolist()
    with pytest.raises(moreau.MoreauError, match="non-empty dict"):
        moreau.sweep_grid(WORKED, {}, tmp_path / "none")
    with pytest.raises(moreau.MoreauError, match="unknown parameter"):
        moreau.sweep_grid(WORKED, {"input.amplitud": [1.0]}, tmp_path / "typo")


def test_diagnose_takes_the_cli_metric_and_no_refit():
    d = moreau.diagnose(BAM_MODEL, BAM_DATA, metric="fit")
    assert d.headline_metric == "fit" and isinstance(d, moreau.Diagnosis)
    assert repr(d).startswith("Diagnosis(verdict=")
    # `sin_time_square` refits the grey-box entries (`sin_sin` needs no refit once the
    # gearbox's load friction is named)
    grey = BAM_MODEL.with_name("bam-xl330-kp100-greybox.toml")
    square = BAM_DATA.with_name("xl330-kp100-sin_time_square.csv")
    refit = moreau.diagnose(grey, square, metric="rmse")
    kept = moreau.diagnose(grey, square, metric="rmse", no_refit=True)
    assert refit.headline_metric == kept.headline_metric == "rmse"
    assert refit.nominal_refit and not kept.nominal_refit, (refit.nominal_refit, kept.nominal_refit)
    with pytest.raises(moreau.MoreauError, match="possible values: auto, fit, rmse"):
        moreau.diagnose(BAM_MODEL, BAM_DATA, metric="r2")


def test_diagnose_takes_the_cli_screen_samples():
    # the BAM log (1,132 samples on its uniform grid) is longer than twice 300: screened on
    # its first 300, every reported number the whole record's
    screened = moreau.diagnose(BAM_MODEL, BAM_DATA, screen_samples=300)
    assert screened["screening"]["samples"] == 300, screened.get("screening")
    assert screened.samples == 1132
    assert screened.notes[0].startswith("Record of 1132 samples: the hypotheses were screened on its first 300")
    # the default (4,000) and 0 (never) leave a short record whole
    assert "screening" not in moreau.diagnose(BAM_MODEL, BAM_DATA)
    assert "screening" not in moreau.diagnose(BAM_MODEL, BAM_DATA, screen_samples=0)


def test_figures_from_python_for_a_system_and_a_sweep(tmp_path):
    sysm = moreau.load(WORKED)
    files = moreau.figure("psi", sysm, tmp_path / "figs", size="column", formats="svg", title=False)
    assert [f.rsplit("/", 1)[-1] for f in files] == ["fig-psi1.svg"]
    svg = open(files[0], encoding="utf-8").read()
    assert svg.startswith("<svg") and 'width="252"' in svg
    grid = moreau.sweep_grid(WORKED, {"input.amplitude": [1.0, 2.0]}, tmp_path / "grid", evaluate={"measure": False})
    files = moreau.figure("sweep", grid, tmp_path / "figs2", formats=["svg", "pgf"], columns=["theta", "theta_best"])
    assert sorted(f.rsplit(".", 1)[-1] for f in files) == ["csv", "svg", "tex"]
    with pytest.raises(moreau.MoreauError, match="possible values: psi, tube, trajectory, sweep"):
        moreau.figure("psy", sysm, tmp_path / "bad")
    with pytest.raises(moreau.MoreauError, match="possible values: column, two-column"):
        moreau.figure("psi", sysm, tmp_path / "bad", size="wide")
