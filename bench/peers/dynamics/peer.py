"""NumPy peer of the catching-up scheme on the worked example (n = 2, p = 1, Theta = [-0.1, 0.1],
w = sin t, h = 1e-3, exact linear step with w linearly interpolated): a straightforward loop and a
vectorised ensemble of 1,000 trajectories. Prints steps/s."""
import sys, time
import numpy as np
from scipy.linalg import expm

A = np.array([[0.0, 1.0], [-2.0, -0.6]]); B = np.array([0.0, 1.0]); E = np.array([0.0, 1.0]); C = np.array([1.0, 0.0])
h = 1e-3; n = 2
M = np.zeros((3 * n, 3 * n)); M[:n, :n] = A * h; M[:n, n:2 * n] = np.eye(n) * h; M[n:2 * n, 2 * n:] = np.eye(n) * h
X = expm(M); Phi, G1, G2 = X[:n, :n], X[:n, n:2 * n], X[:n, 2 * n:]
g1e, g1b, g2b = G1 @ E, G1 @ B, G2 @ B / h

def single(steps):
    x = np.zeros(2); z = 0.0
    for k in range(steps):
        w0, w1 = np.sin(k * h), np.sin((k + 1) * h)
        x = Phi @ x + g1e * z + g1b * w0 + g2b * (w1 - w0)
        y = x[0]
        z = y + min(max(z - y, -0.1), 0.1)
    return x

def ensemble(m, steps):
    x = np.zeros((m, 2)); x[:, 0] = 0.01 * np.arange(m) / m; z = x[:, 0].copy()
    for k in range(steps):
        w0, w1 = np.sin(k * h), np.sin((k + 1) * h)
        x = x @ Phi.T + np.outer(z, g1e) + g1b * w0 + g2b * (w1 - w0)
        y = x[:, 0]
        z = y + np.clip(z - y, -0.1, 0.1)
    return x

steps = int(sys.argv[1]) if len(sys.argv) > 1 else 200_000
ens_steps = int(sys.argv[2]) if len(sys.argv) > 2 else 10_000
t = time.perf_counter(); single(steps); dt = time.perf_counter() - t
print(f"numpy_single {steps / dt:.6e}")
t = time.perf_counter(); ensemble(1000, ens_steps); dt = time.perf_counter() - t
print(f"numpy_ensemble {1000 * ens_steps / dt:.6e}")
