"""Sets, inputs and systems: built from numpy arrays, validated by the model-file reader (same
checks, same messages as the CLI reading the equivalent file), python-control import."""
import numpy as np
import pytest

import moreau

from conftest import EXAMPLES, WORKED

A = np.array([[0.0, 1.0], [-2.0, -0.6]])
B = np.array([[0.0], [1.0]])
C = np.array([[1.0, 0.0]])
E = np.array([[0.0], [1.0]])


def worked(**kw):
    kw.setdefault("theta", moreau.Interval(0.1))
    kw.setdefault("input", moreau.Sine([1.0], omega=1.0))
    return moreau.System(A, B, C, E, **kw)


def test_system_from_arrays_is_the_worked_example_file():
    sys = worked(name="worked example (NOTES.md), a = 1", x0=[0.0, 0.0], z0=[0.0])
    assert sys.to_toml() == moreau.load(WORKED).to_toml()
    # an initial state that was not given is not written (it would then count as known)
    assert "[initial]" not in worked(name="worked example (NOTES.md), a = 1").to_toml()
    assert (sys.n, sys.m, sys.p) == (2, 1, 1)
    assert sys.period == pytest.approx(2 * np.pi)
    assert sys.mu == pytest.approx(-0.3)
    assert np.array_equal(sys.A, A) and np.array_equal(sys.F, A + E @ C)
    assert sys.theta == "interval [-0.1, 0.1]" and sys.R == pytest.approx(0.1)
    assert np.allclose(sys.w([0.0, np.pi / 2]), [[0.0], [1.0]])
    assert "n = 2, m = 1, p = 1" in repr(sys)


def test_save_and_load_round_trip(tmp_path):
    sys = worked(x0=[0.05, 0.0], dt=2e-3, periods=5)
    path = tmp_path / "m.toml"
    sys.save(path)
    back = moreau.load(path)
    assert back.to_toml() == sys.to_toml()
    assert np.array_equal(back.x0, [0.05, 0.0]) and np.array_equal(back.z0, [0.05])  # z0 = C x0
    assert (back.dt, back.periods) == (2e-3, 5)


def test_sets():
    assert moreau.Interval(-0.2, 0.1).describe() == "interval [-0.2, 0.1]"
    b = moreau.Ball(0.5, centre=[0.1, 0.0])
    assert b.dim == 2 and b.R == pytest.approx(0.5)
    e = moreau.Ellipsoid(semi_axes=[0.2, 0.1])
    assert e.R == pytest.approx(0.2**2 / 0.1, rel=1e-9)
    em = moreau.Ellipsoid(matrix=[[0.04, 0.0], [0.0, 0.01]])
    assert em.R == pytest.approx(e.R, rel=1e-9)
    assert moreau.Polytope([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]], [1, 1, 1, 1]).R == float("inf")
    assert moreau.Box([-1, -1], [1, 1]).dim == 2
    lens = moreau.BallIntersection([[0.5, 0.0], [-0.5, 0.0]], [1.0, 1.0])
    assert lens.R == pytest.approx(1.0)
    # a ball without centre takes the dimension of the system
    sys2 = moreau.System(np.diag([-1.0, -2.0]), np.eye(2), np.eye(2), -0.1 * np.eye(2), theta=moreau.Ball(0.3))
    assert sys2.p == 2 and sys2.theta.startswith("ball")


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: moreau.Interval(-0.1), "key `theta.half_width`: must be non-negative (value -0.1)"),
        (lambda: moreau.Interval(0.2, 0.1), "interval lower end 0.2 exceeds upper end 0.1"),
        (lambda: moreau.Ellipsoid(semi_axes=[0.1, -1.0]), "key `theta.semi_axes`: semi-axes must be positive (value -1)"),
        (lambda: moreau.Ellipsoid(matrix=[[1.0, 2.0], [2.0, 1.0]]), "not symmetric positive definite"),
        (lambda: moreau.Ellipsoid([1.0], matrix=[[1.0]]), "exclude each other"),
        (lambda: moreau.Ball(0.1, centre=[1.0, 0.0]), "Theta does not contain 0"),
    ],
)
def test_bad_sets_raise_moreau_errors(make, message):
    with pytest.raises(moreau.MoreauError) as e:
        make()
    assert message in str(e.value)
    assert isinstance(e.value, ValueError)


def test_bad_systems_fail_as_the_equivalent_model_file_does(cli, tmp_path):
    cases = [
        dict(B=np.array([[1.0]])),
        dict(E=np.array([[0.0, 1.0]])),
        dict(input=moreau.Sine([1.0, 2.0], omega=1.0)),
        dict(input=moreau.Sine([1.0], omega=-1.0)),
        dict(A=np.array([[np.nan, 1.0], [-2.0, -0.6]])),
        dict(x0=[1.0, 0.0], z0=[0.0]),
        dict(theta=moreau.Ball(0.1, centre=[0.0, 0.0])),
        dict(dt=2.0),
    ]
    for i, kw in enumerate(cases):
        args = dict(A=A, B=B, C=C, E=E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0), name="bad")
        args.update(kw)
        with pytest.raises(moreau.MoreauError) as e:
            moreau.System(args.pop("A"), args.pop("B"), args.pop("C"), args.pop("E"), **args)
        mine = str(e.value)
        # the same model as a file, through the CLI
        text = _toml(**{**dict(A=A, B=B, C=C, E=E), **{k: v for k, v in kw.items() if k in "ABCE"}})
        text += _rest(kw)
        path = tmp_path / f"bad{i}.toml"
        path.write_text(text)
        ref = cli.error("validate", path)
        assert ref == f"{path}: {mine}", (ref, mine)
        assert moreau.MoreauError  # and the Python error for the file is the CLI's
        with pytest.raises(moreau.MoreauError) as e2:
            moreau.load(path)
        assert str(e2.value) == ref


def _arr(a):
    return "[" + ", ".join("[" + ", ".join(repr(float(x)).replace("nan", "nan") for x in row) + "]" for row in np.asarray(a)) + "]"


def _toml(A, B, C, E):
    return f'name = "bad"\n[plant]\nA = {_arr(A)}\nB = {_arr(B)}\nC = {_arr(C)}\nE = {_arr(E)}\n'


def _rest(kw):
    theta = kw.get("theta", moreau.Interval(0.1))
    inp = kw.get("input", moreau.Sine([1.0], omega=1.0))
    s = "[theta]\n" + "".join(f"{k} = {_val(v)}\n" for k, v in theta.table.items())
    s += "[input]\n" + "".join(f"{k} = {_val(v)}\n" for k, v in inp.table.items())
    if "x0" in kw:
        s += f"[initial]\nx0 = {_val(kw['x0'])}\nz0 = {_val(kw['z0'])}\n"
    if "dt" in kw:
        s += f"[simulation]\ndt = {_val(kw['dt'])}\n"
    return s


def _val(v):
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_val(x) for x in v) + "]"
    return repr(float(v))


def test_wrong_shapes_and_types():
    with pytest.raises(moreau.MoreauError, match="key `plant.B`: expected a 2-D array"):
        moreau.System(A, [0.0, 1.0], C, E)
    with pytest.raises(moreau.MoreauError, match="key `plant.A`: expected a matrix"):
        moreau.System([[0.0, 1.0], [2.0]], B, C, E)
    with pytest.raises(TypeError, match="theta must be a moreau set"):
        moreau.System(A, B, C, E, theta=0.1)
    with pytest.raises(TypeError, match="expected a moreau.System or the path"):
        moreau.theta(42)


class StateSpace:
    """A stand-in for python-control's StateSpace (only the attributes moreau reads)."""

    def __init__(self, A, B, C, D, dt=0, name="plant"):
        self.A, self.B, self.C, self.D, self.dt, self.name = (np.asarray(A), np.asarray(B), np.asarray(C), np.asarray(D), dt, name)


def test_from_statespace():
    ss = StateSpace(A, B, C, [[0.0]])
    sys = moreau.System.from_statespace(ss, E=E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0))
    assert sys.name == "plant"
    assert moreau.theta(sys, measure=False, stationary=False)["theta"] == pytest.approx(-0.017232, abs=1e-6)
    named = moreau.System.from_statespace(ss, E, moreau.Interval(0.1), name="other")
    assert named.name == "other" and named.input_kind == "zero"
    with pytest.raises(moreau.MoreauError, match="direct feedthrough D != 0"):
        moreau.System.from_statespace(StateSpace(A, B, C, [[1.0]]), E=E)
    with pytest.raises(moreau.MoreauError, match="discrete-time"):
        moreau.System.from_statespace(StateSpace(A, B, C, [[0.0]], dt=0.1), E=E)
    with pytest.raises(TypeError, match="attributes A, B, C"):
        moreau.System.from_statespace(object(), E=E)


def test_from_python_control_statespace():
    control = pytest.importorskip("control")
    ss = control.ss(A, B, C, 0)
    sys = moreau.System.from_statespace(ss, E=E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0))
    assert np.array_equal(sys.A, A)


def test_inputs():
    sq = worked(input=moreau.Square([2.0], omega=2.0, phase=0.1))
    assert sq.input_kind == "square" and sq.period == pytest.approx(np.pi)
    t = np.linspace(0, 10, 101)
    smp = worked(input=moreau.Samples(t, np.sin(t), period=10.0))
    assert smp.input_kind == "csv" and smp.period == 10.0
    assert np.allclose(smp.w(t[:5]).ravel(), np.sin(t[:5]))
    with pytest.raises(moreau.MoreauError, match="time stamps must increase strictly"):
        worked(input=moreau.Samples([0.0, 1.0, 1.0], [0.0, 1.0, 2.0]))
    with pytest.raises(moreau.MoreauError, match="key `input.period`: shorter than the data"):
        worked(input=moreau.Samples(t, np.sin(t), period=5.0))
    with pytest.raises(moreau.MoreauError, match="key `input`: expected m = 1 components"):
        worked(input=moreau.Samples(t, np.zeros((len(t), 2)), period=10.0))
    assert worked(input=moreau.Zero()).period is None
    tr = moreau.simulate(worked(input=moreau.Zero(), x0=[0.5, 0.0]), t_end=3.0)
    assert tr["w"].shape[1] == 1 and not tr["w"].any()


def test_models_with_effects_are_ordinary_systems(tmp_path):
    sys = worked(effects=[{"kind": "coulomb_friction", "state": 1, "level": 0.05}])
    assert sys.effects == ["coulomb_friction"]
    rep = moreau.theta(sys, measure=False, stationary=False, guidance=False)
    assert rep["effects"] and rep["theta_verified"] is False
    assert moreau.simulate(sys, periods=1).method.startswith("extended model with coulomb_friction")


def test_every_example_loads_and_converts(tmp_path):
    for f in sorted(EXAMPLES.glob("*.toml")):
        s = moreau.load(f)
        rebuilt = moreau.System(s.A, s.B, s.C, s.E, name=s.name)
        assert rebuilt.n == s.n and rebuilt.p == s.p


def test_a_multisine_input_is_the_model_files_and_is_certified():
    ms = moreau.Multisine([1.0], omega=1.0, harmonics=[1, 3, 5], weights=[1.0, 0.3, 0.1], phases=[0.0, 0.4, 1.0])
    sys = worked(input=ms)
    assert sys.period == pytest.approx(2 * np.pi)
    t = np.array([0.3, 1.7])
    expect = np.sin(t) + 0.3 * np.sin(3 * t + 0.4) + 0.1 * np.sin(5 * t + 1.0)
    assert np.allclose(sys.w(t)[:, 0], expect)
    r = moreau.theta(sys, measure=False)
    assert r.theta_verified and r.theta < 0
    with pytest.raises(moreau.MoreauError, match=r"input\.harmonics\[0\].*whole multiple"):
        worked(input=moreau.Multisine([1.0], omega=1.0, harmonics=[0.5]))


def test_samples_take_the_csv_inputs_hold():
    t = np.linspace(0.0, 2 * np.pi, 32, endpoint=False)
    zoh = worked(input=moreau.Samples(t, np.sin(t), period=2 * np.pi, hold="zoh"))
    foh = worked(input=moreau.Samples(t, np.sin(t), period=2 * np.pi))
    mid = 0.5 * (t[3] + t[4])
    assert zoh.w([mid])[0, 0] == pytest.approx(np.sin(t[3]))
    assert foh.w([mid])[0, 0] == pytest.approx(0.5 * (np.sin(t[3]) + np.sin(t[4])))
    with pytest.raises(moreau.MoreauError, match=r"input\.hold.*cubic"):
        worked(input=moreau.Samples(t, np.sin(t), period=2 * np.pi, hold="cubic"))
