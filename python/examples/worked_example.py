# %% [markdown]
# # The worked example from Python
#
# A notebook-style script (cells marked `# %%`: open it in Jupyter with jupytext, in VS Code or
# Spyder, or run it as `python python/examples/worked_example.py` from the repository root).
# It is the worked example of `../shared/paper/NOTES.md`: a second-order plant with a gear
# backlash of half-width 0.1 driven by `w = sin t`,
#
#     x' = A x + B w + E z,   y = C x,   z in y + Theta,   Theta = [-0.1, 0.1].
#
# Every number below is what the `moreau` command prints for the same model.

# %%
import os
import sys

import numpy as np

import moreau

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# %% [markdown]
# ## 1. The model from numpy arrays

# %%
A = np.array([[0.0, 1.0], [-2.0, -0.6]])
B = np.array([[0.0], [1.0]])
C = np.array([[1.0, 0.0]])
E = np.array([[0.0], [1.0]])
plant = moreau.System(A, B, C, E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0), name="worked example")
print(plant)
print("eig(F) =", plant.eig_F(), " R =", plant.R)

# %% [markdown]
# ## 2. The certificate theta (eq. (theta))
#
# `moreau.theta` returns the dict of `moreau theta FILE --json`: one key per quantity, the
# verified flags, and the list `quantities` with the equation, the bound direction and how
# each number was obtained.

# %%
report = moreau.theta(plant)
print(f"theta = {report['theta']:.6f}  verified: {report['theta_verified']}")
print(f"best certified bound {report['theta_best_method']} = {report['theta_best']:.6f}")
print(f"measured exponent {report['measured_rate']:.4f}, 95% CI {report['measured_rate_ci']}")
print()
print(f"{'symbol':<30} {'eq.':<16} {'value':>12}  {'kind':<9} verified")
for q in report["quantities"]:
    value = "n/a" if q["value"] is None else f"{q['value']:.6f}"  # None: not finite
    print(f"{q['symbol']:<30} {q.get('equation', ''):<16} {value:>12}  {q['kind']:<9} {q['verified']}")

# %% [markdown]
# ## 3. From python-control
#
# Any object with attributes `A`, `B`, `C` (and a zero `D`) will do; with python-control
# installed this is `control.ss(A, B, C, 0)`.

# %%
try:
    import control

    ss = control.ss(A, B, C, 0)
except ImportError:  # the same thing without python-control
    class _SS:
        A, B, C, D, dt, name = A, B, C, np.zeros((1, 1)), 0, "plant"

    ss = _SS()
from_ss = moreau.System.from_statespace(ss, E=E, theta=moreau.Interval(0.1), input=moreau.Sine([1.0], omega=1.0))
print("theta from the StateSpace:", moreau.theta(from_ss, measure=False, stationary=False)["theta"])

# %% [markdown]
# ## 4. Simulation and the periodic regime
#
# `simulate` returns numpy arrays: `t` (N,), `w`, `x`, `y`, `z`, `q = z - y` (N, k).

# %%
tr = moreau.simulate(plant, periods=5)
print(tr.method, {k: v.shape for k, v in tr.items()})
print("max |z - y| =", np.abs(tr["q"]).max(), "(stays in Theta)")
reg = moreau.periodic(plant, periods=20, pairs=1)
print("periodic regime x(0) =", reg["periodic_regime"]["x0"], " exponent", reg["rate"]["exponent"])

# %%
try:
    import matplotlib

    if "ipykernel" not in sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3))
    ax.plot(tr["t"], tr["w"][:, 0], label="input w")
    ax.plot(tr["t"], tr["y"][:, 0], label="output y")
    ax.plot(tr["t"], tr["z"][:, 0], label="backlash z")
    ax.set_xlabel("t (s)")
    ax.legend(loc="upper right")
    fig.tight_layout()
    if "ipykernel" not in sys.modules:
        fig.savefig(os.path.join(os.environ.get("MOREAU_EXAMPLE_OUT", "."), "worked_example_trajectory.png"), dpi=150)
except ImportError:
    print("(matplotlib not installed: no plot)")

# %% [markdown]
# ## 5. A sweep over the amplitude, by hand
#
# The bound gets sharper as the backlash moves more of the time.

# %%
for a in (0.5, 1.0, 2.0, 5.0):
    s = moreau.System(A, B, C, E, theta=moreau.Interval(0.1), input=moreau.Sine([a], omega=1.0))
    r = moreau.theta(s, measure=False, stationary=False, guidance=False)
    print(f"a = {a:4}: theta = {r['theta']:+.5f}, best {r['theta_best']:+.5f} ({r['theta_best_method']}), certified {r['convergence_guaranteed']}")

# %% [markdown]
# ## 6. Checking a lemma of the paper, and diagnosing a recording

# %%
res = moreau.check(only="lemma_a2", cases=500)
print(res["results"][0]["title"], "->", "passed" if res.passed else "VIOLATED", f"(min slack {res['results'][0]['min_slack']:.3e})")

model = moreau.load(os.path.join(ROOT, "examples", "real", "bam-xl330-kp100.toml"))
recording = np.loadtxt(os.path.join(ROOT, "data", "bam-servo", "xl330-kp100-sin_sin.csv"), delimiter=",", skiprows=1)
d = moreau.diagnose(model, recording)  # columns t, w, y (a pandas DataFrame works too)
print(d["verdict"])

# %% [markdown]
# ## 7. Errors
#
# Every error is a `moreau.MoreauError` (a `ValueError`) with the CLI's one-line message.

# %%
try:
    moreau.System(A, np.array([[1.0]]), C, E)
except moreau.MoreauError as e:
    print("error:", e)
