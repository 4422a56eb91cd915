"""Issue 31 item 8: arguments the package once accepted silently or misreported. Each is now
refused naming the argument (TypeError, or MoreauError, a ValueError, with the CLI's message);
each test has a control that the well-formed call still works."""
import numpy as np
import pytest

import moreau
from moreau import _native

A = np.array([[0.0, 1.0], [-2.0, -0.6]])
B = np.array([[0.0], [1.0]])
C = np.array([[1.0, 0.0]])
E = np.array([[0.0], [1.0]])


def build(A=A, B=B, C=C, E=E, **kw):
    kw.setdefault("theta", moreau.Interval(0.1))
    kw.setdefault("input", moreau.Sine([1.0], omega=1.0))
    return moreau.System(A, B, C, E, **kw)


def test_complex_arrays_are_refused_not_stripped_of_their_imaginary_part():
    for bad in (A * (1 + 1e-3j), A.astype(complex), [[0.0, 1.0], [-2.0, -0.6 + 1j]]):
        with pytest.raises(TypeError, match=r"`plant\.A`.*complex.*imaginary part would be dropped"):
            build(A=bad)
    with pytest.raises(TypeError, match=r"`theta\.radius`.*complex"):
        moreau.Ball(np.complex128(0.5 + 0.1j))
    with pytest.raises(TypeError, match=r"`theta\.normals`.*complex"):
        moreau.Polytope(np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]) * 1j, [1, 1, 1, 1])
    with pytest.raises(TypeError, match=r"`<samples>: w`.*complex"):
        moreau.Samples([0.0, 1.0, 2.0], [0.0, 1j, 0.0])
    # the native layer refuses a complex entry of a raw table too
    with pytest.raises(TypeError, match=r"key `plant\.A`: a complex number"):
        _native.System.from_table({"plant": {"A": [[1 + 2j]], "B": [[1.0]], "C": [[1.0]], "E": [[0.0]]}})
    # a purely imaginary feedthrough D is not zero
    class SS:
        A, B, C, D = A, B, C, np.array([[1j]])

    with pytest.raises(TypeError, match=r"`D` is complex"):
        moreau.System.from_statespace(SS, E, moreau.Interval(0.1))
    # control: real arrays of any real dtype
    assert build(A=A.astype(np.float32)).n == 2


def test_periods_must_be_whole_as_in_the_model_file():
    with pytest.raises(moreau.MoreauError, match=r"key `simulation\.periods`: must be a positive integer \(value 2\.5\)"):
        build(periods=2.5)
    sys = build(periods=3.0)
    assert sys.periods == 3
    assert build(periods=np.int64(4)).periods == 4
    with pytest.raises(moreau.MoreauError, match=r"`periods` = 2\.5: must be a whole number"):
        moreau.simulate(sys, periods=2.5)
    with pytest.raises(moreau.MoreauError, match=r"`periods` = 2\.5"):
        moreau.periodic(sys, periods=2.5)
    # control: a whole number of periods runs
    assert moreau.simulate(sys, periods=1.0, dt=1e-2)["t"][-1] == pytest.approx(2 * np.pi)


def test_model_size_has_the_cli_budget_declared_once():
    limit = _native.MAX_MODEL_NUMBERS
    assert limit == (16 << 20) // 16  # the model-file limit of the CLI, at 16 bytes a number
    n = 3000  # 9e6 numbers in A: gigabytes once converted, before the fix
    with pytest.raises(moreau.MoreauError, match=r"model: 9000000 numbers \(`plant\.A` of shape \(3000, 3000\)\) exceed the limit 1048576"):
        moreau.System(-np.eye(n), np.ones((n, 1)), np.ones((1, n)), np.zeros((n, 1)))
    # the native layer counts a raw table's numbers itself
    big = [[0.0] * 1100 for _ in range(1000)]
    with pytest.raises(moreau.MoreauError, match=r"exceed the limit 1048576"):
        _native.System.from_table({"plant": {"A": big, "B": [[1.0]], "C": [[1.0]], "E": [[0.0]]}})
    with pytest.raises(moreau.MoreauError, match=r"input samples: .* exceed the limit"):
        _native.check_sample_numbers(_native.MAX_SAMPLE_NUMBERS + 1, "t and w")
    # control: a 300-state chain builds
    m = 300
    s = moreau.System(-np.eye(m), np.ones((m, 1)), np.eye(1, m), np.zeros((m, 1)))
    assert s.n == m


def test_a_missing_argument_is_named_not_reported_as_nan():
    with pytest.raises(TypeError, match=r"`plant\.A` is missing \(None\)"):
        moreau.System(None, B, C, E)
    with pytest.raises(TypeError, match=r"`plant\.E` is missing \(None\)"):
        moreau.System(A, B, C, None)
    with pytest.raises(TypeError, match=r"`plant\.A` has a None entry"):
        moreau.System([[None, 1.0], [-2.0, -0.6]], B, C, E)
    with pytest.raises(TypeError, match=r"`theta\.half_width` is missing \(None\)"):
        moreau.Interval(None)
    for call in (lambda: moreau.System(None, B, C, E), lambda: moreau.Interval(None)):
        with pytest.raises(TypeError) as e:
            call()
        assert "NaN" not in str(e.value)


def test_sampled_inputs_need_a_period_the_data_cover():
    with pytest.raises(moreau.MoreauError, match=r"key `input\.period`: longer than the data in `<samples>` cover: the samples span 2"):
        build(input=moreau.Samples([0.0, 1.0, 2.0], [0.0, 1.0, 0.0], period=1e12))
    assert build(input=moreau.Samples([0.0, 1.0, 2.0], [0.0, 1.0, 0.0], period=3.0)).period == 3.0
