"""Peer cross-check of `load_friction` on the BAM XL330 logs (issue 28).

An independent NumPy model of the servo-pendulum written in the form of the BAM actuator
models (Rhoban/bam, Apache-2.0; the friction budget of their model M3, the stopping-torque
clipping of their simulator): nonlinear gravity `-m g l sin(q + q_offset)`, motor torque
`kt/R (V - kt dq)` with `V = error_gain kp (goal - q) vin` clipped to the supply, friction
budget `Kc + Kl |tau_e - tau_m| + Kv |dq|` (M3) or `Kc + Kv |dq|` (M1). Fitted by SciPy least
squares on one log, on two (the third left out) and on all three; prints RMSE (mrad) over
each whole record. Nothing here is shared with the Rust code.

Usage: python bam_m3.py DATA_DIR   (DATA_DIR: data/bam-servo of the repository)
"""
import sys
import numpy as np
from scipy.optimize import least_squares

LOGS = ["sin_sin", "sin_time_square", "up_and_down"]
MASS, LENGTH, KP, VIN, G = 0.49, 0.1, 100.0, 7.4, 9.81
KT, R = 0.3866957639281311, 4.017129222290597  # upstream m1.json
ERROR_GAIN = 0.04259 / VIN  # V/rad per firmware unit of kp, over the supply
NAMES = ["gain_scale", "armature", "Kc", "Kv", "q_offset", "Kl"]


def load(data_dir, name):
    a = np.loadtxt(f"{data_dir}/xl330-kp100-{name}.csv", delimiter=",", skiprows=1)
    return a[:, 0], a[:, 1], a[:, 2]


def simulate(x, t, w, y, substeps=4):
    gain, armature, kc, kv, q_off, kl = x
    inertia = armature + MASS * LENGTH**2
    q, dq = y[0], 0.0
    out = np.empty_like(y)
    for k in range(len(t)):
        out[k] = q
        if k == len(t) - 1:
            break
        h = (t[k + 1] - t[k]) / substeps
        for _ in range(substeps):
            volts = np.clip(ERROR_GAIN * gain * KP * (w[k] - q), -1.0, 1.0) * VIN
            tau_m = KT * volts / R - KT * KT * dq / R
            tau_e = -MASS * G * LENGTH * np.sin(q + q_off)
            budget = kc + kl * abs(tau_e - tau_m) + kv * abs(dq)
            net = tau_m + tau_e
            stop = inertia / h * dq + net
            net -= np.sign(stop) * min(abs(stop), budget)
            dq += net / inertia * h
            q += dq * h
    return out


def rmse(x, rec):
    t, w, y = rec
    return 1000.0 * np.sqrt(np.mean((simulate(x, t, w, y) - y) ** 2))


def fit(recs, load_dependent):
    x0 = [1.0, 0.0018, 0.0128, 0.0037, 0.0, 0.1 if load_dependent else 0.0]
    lo = [0.3, 1e-4, 0.0, 0.0, -0.1, 0.0]
    hi = [2.0, 0.02, 0.5, 0.5, 0.1, 1.0 if load_dependent else 1e-12]

    def residual(x):
        return np.concatenate([simulate(x, *r) - r[2] for r in recs])

    return least_squares(residual, x0, bounds=(lo, hi), diff_step=1e-3, max_nfev=200).x


def main(data_dir):
    recs = {n: load(data_dir, n) for n in LOGS}
    for model, load_dependent in [("M1", False), ("M3", True)]:
        own = {n: rmse(fit([recs[n]], load_dependent), recs[n]) for n in LOGS}
        joint_x = fit(list(recs.values()), load_dependent)
        for n in LOGS:
            left_x = fit([recs[m] for m in LOGS if m != n], load_dependent)
            left = rmse(left_x, recs[n])
            print(f"{model} {n}: own {own[n]:.1f} left_out {left:.1f} joint {rmse(joint_x, recs[n]):.1f} "
                  f"ratio {left / own[n]:.2f}", flush=True)
        print(f"{model} joint parameters: " + ", ".join(f"{k} {v:.4g}" for k, v in zip(NAMES, joint_x)), flush=True)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "data/bam-servo")
