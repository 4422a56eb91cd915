"""simulate, periodic, check, diagnose, sweep and theta's options: the same numbers as the
corresponding `moreau` commands, numpy arrays in and out."""
import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest

import moreau

from conftest import EXAMPLES, ROOT, WORKED

BAM_MODEL = EXAMPLES / "real" / "bam-xl330-kp100.toml"
BAM_DATA = ROOT / "data" / "bam-servo" / "xl330-kp100-sin_sin.csv"


def test_theta_options_are_the_cli_flags(cli):
    assert moreau.theta(WORKED, measure=False, stationary=False) == cli.json(
        "theta", WORKED, "--json", "--no-measure", "--no-stationary"
    )


def test_guidance_key_only_when_nothing_is_certified_as_in_the_cli(cli):
    poly = EXAMPLES / "polytope-p2.toml"
    with_guidance = moreau.theta(poly, measure=False, stationary=False)
    assert with_guidance == cli.json("theta", poly, "--json", "--no-measure", "--no-stationary")
    assert "guidance" in with_guidance and not with_guidance["convergence_guaranteed"]
    without = moreau.theta(poly, measure=False, stationary=False, guidance=False)
    assert "guidance" not in without
    assert {k: v for k, v in with_guidance.items() if k != "guidance"} == without


def test_simulate_returns_the_cli_trajectory_as_arrays(cli, tmp_path):
    out = tmp_path / "sim"
    r = cli.run("simulate", WORKED, "--periods", "2", "--out", out)
    assert r.returncode == 0, r.stderr
    ref = np.loadtxt(out / "trajectory.csv", delimiter=",", skiprows=1)
    tr = moreau.simulate(WORKED, periods=2)
    assert set(tr) == {"t", "w", "x", "y", "z", "q"}
    assert tr["t"].shape == (len(ref),) and tr["x"].shape == (len(ref), 2) and tr["z"].shape == (len(ref), 1)
    mine = np.column_stack([tr["t"], tr["w"], tr["x"], tr["y"], tr["z"], tr["q"]])
    assert np.array_equal(mine, ref)
    assert tr.method.startswith("catching-up, h = ")
    # a Python-built system is the same model
    sys = moreau.load(WORKED)
    assert np.array_equal(moreau.simulate(sys, periods=2)["z"], tr["z"])


def test_simulate_t_end_dt_max_rows_and_event_integrator():
    sys = moreau.load(WORKED)
    tr = moreau.simulate(sys, t_end=5.0, dt=0.01)
    T = 2 * np.pi
    h = T / np.ceil(T / 0.01)
    assert tr.h == pytest.approx(h, rel=1e-15)
    assert tr["t"][-1] == pytest.approx(5.0, abs=h)
    assert np.allclose(tr["q"], tr["z"] - tr["y"], atol=1e-15)
    assert np.all(np.abs(tr["q"]) <= 0.1 + 1e-12)  # z - y stays in Theta = [-0.1, 0.1]
    thin = moreau.simulate(sys, t_end=5.0, dt=0.01, max_rows=50)
    assert len(thin["t"]) <= 51
    ev = moreau.simulate(sys, periods=1, integrator="event")
    assert ev.method.startswith("event-driven")
    cu = moreau.simulate(sys, periods=1)
    assert abs(ev["x"][-1] - cu["x"][-1]).max() < 1e-2
    with pytest.raises(moreau.MoreauError, match="possible values: catching-up, event"):
        moreau.simulate(sys, integrator="rk4")
    with pytest.raises(moreau.MoreauError, match="give t_end or periods, not both"):
        moreau.simulate(sys, t_end=1.0, periods=1)


def test_periodic_is_the_cli_object(cli):
    args = dict(periods=12, pairs=1)
    assert moreau.periodic(WORKED, **args) == cli.json("periodic", WORKED, "--json", "--periods", "12", "--pairs", "1")


def test_check_is_the_cli_campaign(cli):
    mine = moreau.check(only="lemma_a2", cases=300, seed=7)
    ref = cli.json("check", "--only", "lemma_a2", "--cases", "300", "--seed", "7", "--json")
    strip = lambda d: {**d, "results": [{k: v for k, v in r.items() if k != "seconds"} for r in d["results"]]}
    assert strip(mine) == strip(ref)
    assert mine.passed and mine["results"][0]["violations"] == 0
    neg = moreau.check(only="lemma_a2", cases=300, negative_control=True)
    assert neg["variant"] == "negative_control" and neg.passed  # the control found its counterexample
    assert neg["results"][0]["counterexample_file"] is None  # no out=: no files


class FakeFrame:
    """The part of a pandas DataFrame that diagnose uses (columns, to_csv)."""

    def __init__(self, names, data):
        self.columns = list(names)
        self._data = data

    def to_csv(self, index=False):
        buf = io.StringIO()
        np.savetxt(buf, self._data, delimiter=",", fmt="%.17g", header=",".join(self.columns), comments="")
        return buf.getvalue()


def _recording():
    with open(BAM_DATA) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


def test_diagnose_from_a_csv_path_matches_the_cli_report(cli, tmp_path):
    out = tmp_path / "diag"
    r = cli.run("diagnose", "--model", BAM_MODEL, "--data", BAM_DATA, "--out", out)
    assert r.returncode == 0, r.stderr
    ref = json.loads((out / "report.json").read_text())
    mine = moreau.diagnose(BAM_MODEL, BAM_DATA, out=tmp_path / "mine")
    assert dict(mine) == ref
    assert (tmp_path / "mine" / "fitted.toml").exists()
    assert mine.fitted_model is None or isinstance(mine.fitted_model, moreau.System)
    s = mine.series
    assert s["t"].ndim == 1 and s["y"].shape == (len(s["t"]), 1) == s["yhat_fitted"].shape


def test_diagnose_takes_a_list_of_recordings_as_the_cli_does(cli, tmp_path):
    # several recordings of one machine: `--data A --data B`, one model fitted jointly
    model = EXAMPLES / "real" / "bam-xl330-kp100-physical.toml"
    data = [BAM_DATA, ROOT / "data" / "bam-servo" / "xl330-kp100-sin_time_square.csv"]
    out = tmp_path / "joint"
    r = cli.run("diagnose", "--model", model, "--data", data[0], "--data", data[1], "--out", out)
    assert r.returncode == 0, r.stderr
    ref = json.loads((out / "report.json").read_text())
    mine = moreau.diagnose(model, data, out=tmp_path / "mine")
    assert dict(mine) == ref
    assert (tmp_path / "mine" / "fitted.toml").exists()
    assert [row["role"] for row in mine["recordings"]] == ["fit", "fit"]
    assert isinstance(mine.fitted_model, moreau.System) and mine.series is None
    with pytest.raises(TypeError, match="paths"):
        moreau.diagnose(model, [np.zeros((3, 3))])


def test_diagnose_takes_arrays_and_dataframes():
    names, data = _recording()
    by_path = moreau.diagnose(BAM_MODEL, BAM_DATA)
    model = moreau.load(BAM_MODEL)
    for rec in (data, FakeFrame(names, data)):
        d = moreau.diagnose(model, rec)
        assert d["recording"] in ("<array>", "<DataFrame>")
        assert {k: v for k, v in d.items() if k not in ("recording", "model")} == {
            k: v for k, v in by_path.items() if k not in ("recording", "model")
        }
    with pytest.raises(moreau.MoreauError, match="expected 1 \\+ m \\+ p = 3"):
        moreau.diagnose(model, data[:, :2])


def test_diagnose_takes_a_real_pandas_dataframe():
    pd = pytest.importorskip("pandas")
    names, data = _recording()
    d = moreau.diagnose(BAM_MODEL, pd.DataFrame(data, columns=names))
    assert d["recording"] == "<DataFrame>" and d["samples"] > 0


def test_sweep_is_the_cli_table(cli, tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        f'name = "two amplitudes"\nmodel = "{WORKED.as_posix()}"\n'
        '[[axis]]\nparameter = "input.amplitude"\nvalues = [1.0, 5.0]\n'
        '[evaluate]\nmeasure = false\n'
    )
    r = cli.run("sweep", spec, "--out", tmp_path / "cli", "--quiet")
    assert r.returncode == 0, r.stderr
    ref = json.loads((tmp_path / "cli" / "sweep.json").read_text())
    mine = moreau.sweep(spec, tmp_path / "py")
    assert dict(mine) == ref and mine.complete
    assert sorted(Path(f).suffix for f in mine.files) == [".csv", ".json", ".md", ".tex"]
    tab = mine.table
    assert list(tab["input.amplitude"]) == [1.0, 5.0]
    assert tab["theta"].dtype == float and tab["theta"][0] == pytest.approx(-0.0172, abs=1e-3)


def test_an_unstated_x0_stays_unstated_through_save_and_load(tmp_path):
    """A system whose x0 was never given is diagnosed with x0 estimated, and so is the same
    system saved and loaded again: save() writes no `[initial] x0` it was not given (it used to
    write x0 = [0, 0], which then counted as known: 0.220197 vs 0.220007)."""
    text = BAM_MODEL.read_text()
    unstated = text.replace("[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n", "")
    assert unstated != text, "the example's [initial] table moved: update this test"
    built = moreau.System.from_toml(unstated)
    assert "x0" not in built.to_toml()
    path = tmp_path / "saved.toml"
    built.save(path)
    again = moreau.System.load(path)
    d_built = moreau.diagnose(built, BAM_DATA)
    d_again = moreau.diagnose(again, BAM_DATA)
    same = lambda d: {k: v for k, v in d.items() if k not in ("model",)}  # noqa: E731
    assert same(d_built) == same(d_again)
    # negative control: a stated x0 survives the round trip and changes the diagnosis
    stated = moreau.System.from_toml(text)
    assert "x0 = [0.0, 0.0]" in stated.to_toml()
    d_stated = moreau.diagnose(stated, BAM_DATA)
    assert same(d_stated) != same(d_built)
