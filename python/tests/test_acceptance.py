"""Issue 17's acceptance: a five-line script computes theta of the worked example from numpy
arrays and matches the CLI's JSON (`moreau theta examples/worked-example.toml --json
--no-guidance`) exactly."""
import moreau

from conftest import WORKED

SCRIPT = """
import numpy as np, moreau
A, B, C, E = np.array([[0.0, 1.0], [-2.0, -0.6]]), np.array([[0.0], [1.0]]), np.array([[1.0, 0.0]]), np.array([[0.0], [1.0]])
sys = moreau.System(A, B, C, E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0))
report = moreau.theta(sys)
print(f"theta = {report['theta']:.6f} (verified: {report['theta_verified']})")
"""


def test_five_line_script_matches_the_cli_json_exactly(cli, capsys):
    assert len(SCRIPT.strip().splitlines()) == 5
    ns: dict = {}
    exec(SCRIPT, ns)
    report = ns["report"]
    assert "theta = -0.017232 (verified: True)" in capsys.readouterr().out
    expected = cli.json("theta", WORKED, "--json", "--no-guidance")
    # the only difference: the model file names the system, the script does not
    assert report.pop("name") == "system"
    assert expected.pop("name") == "worked example (NOTES.md), a = 1"
    assert report.keys() == expected.keys()
    assert report == expected  # every number bit for bit


def test_named_system_and_model_file_give_the_cli_object_itself(cli):
    expected = cli.json("theta", WORKED, "--json", "--no-guidance")
    sys = moreau.System(
        [[0.0, 1.0], [-2.0, -0.6]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0], [1.0]],
        theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0), name="worked example (NOTES.md), a = 1",
    )
    assert moreau.theta(sys) == expected
    assert moreau.theta(WORKED) == expected  # certified: no guidance key with or without --no-guidance
    assert moreau.theta(str(WORKED), guidance=False) == expected
    assert moreau.theta(moreau.load(WORKED)) == expected
