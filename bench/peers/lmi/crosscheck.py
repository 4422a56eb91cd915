#!/usr/bin/env python3
"""Cross-check of the Rust beta SDP (crates/lmi/src/beta_sdp.rs) against CVXPY + SCS,
and timing of CVXPY + Clarabel against the Rust side.

Problem (paper eqs. (ALI), (G_H), (bet)), for each of the problems written by
`cargo run --release -p lmi --example crosscheck_problems -- --out <dir>`:

    minimise b  s.t.  -(S(Pi F) + lambda Pi) >= delta I,
                      [[Pi, H], [H^T, b I_p]] >= 0,  H = (Pi E - F^T C^T)/2,
                      trace(Pi) <= trace_max.

Usage: .venv/bin/python crosscheck.py <dir>/problems.json [--reps 5]
"""
import json
import sys
import time

import cvxpy as cp
import numpy as np

REL_TOL = 1e-5


def build(prob):
    F = np.array(prob["F"], dtype=float)
    E = np.array(prob["E"], dtype=float)
    C = np.array(prob["C"], dtype=float)
    n, p = prob["n"], prob["p"]
    lam = prob["lambda"]
    Pi = cp.Variable((n, n), symmetric=True)
    b = cp.Variable()
    G = F.T @ C.T
    H = (Pi @ E - G) / 2
    In, Ip = np.eye(n), np.eye(p)
    S = (Pi @ F + F.T @ Pi) / 2
    K = cp.bmat([[Pi, H], [H.T, b * Ip]])
    cons = [
        -(S + lam * Pi) - prob["ali_margin"] * In >> 0,
        (K + K.T) / 2 >> 0,
        cp.trace(Pi) <= prob["trace_max"],
    ]
    return cp.Problem(cp.Minimize(b), cons), b


def solve_scs(prob):
    pr, b = build(prob)
    pr.solve(solver=cp.SCS, eps_abs=1e-11, eps_rel=1e-11, max_iters=500_000)
    return pr.status, float(b.value)


def solve_clarabel(prob):
    t0 = time.perf_counter()
    pr, b = build(prob)
    pr.solve(solver=cp.CLARABEL, tol_gap_abs=1e-9, tol_gap_rel=1e-9, tol_feas=1e-9)
    wall = time.perf_counter() - t0
    return pr.status, float(b.value), wall, pr.solver_stats.solve_time


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        sys.exit(2)
    reps = 5
    if "--reps" in args:
        reps = int(args[args.index("--reps") + 1])
    problems = json.load(open(args[0]))
    print(f"cvxpy {cp.__version__}, solvers: {cp.installed_solvers()}")
    hdr = (f"{'seed':>5} {'n':>2} {'p':>2} {'beta_rust':>14} {'beta_scs':>14} {'rel_scs':>9} "
           f"{'beta_cvx_clar':>14} {'rel_clar':>9} {'rust_ms':>8} {'cvx+clar_ms':>11} {'clar_core_ms':>12} {'ratio':>7}")
    print(hdr)
    rows, ok = [], True
    for prob in problems:
        st_s, b_s = solve_scs(prob)
        runs = [solve_clarabel(prob) for _ in range(reps)]
        st_c, b_c = runs[0][0], runs[0][1]
        wall = float(np.median([r[2] for r in runs]))
        core = float(np.median([r[3] for r in runs]))
        br = prob["beta_rust"]
        scale = max(abs(br), 1e-12)
        rel_s = abs(b_s - br) / scale
        rel_c = abs(b_c - br) / scale
        ratio = wall / prob["rust_solve_s"]
        good = rel_s <= REL_TOL and st_s == "optimal"
        ok &= good
        rows.append(dict(seed=prob["seed"], n=prob["n"], p=prob["p"], beta_rust=br, beta_scs=b_s,
                         status_scs=st_s, rel_scs=rel_s, beta_cvxpy_clarabel=b_c, status_clarabel=st_c,
                         rel_clarabel=rel_c, rust_ms=prob["rust_solve_s"] * 1e3, cvxpy_clarabel_ms=wall * 1e3,
                         clarabel_core_ms=core * 1e3, ratio=ratio, agree=good))
        print(f"{prob['seed']:>5} {prob['n']:>2} {prob['p']:>2} {br:>14.8e} {b_s:>14.8e} {rel_s:>9.1e} "
              f"{b_c:>14.8e} {rel_c:>9.1e} {prob['rust_solve_s']*1e3:>8.3f} {wall*1e3:>11.3f} {core*1e3:>12.3f} "
              f"{ratio:>7.1f}{'' if good else '  <-- DISAGREE'}")
    ratios = [r["ratio"] for r in rows]
    print(f"\nagreement (SCS vs Rust, rel <= {REL_TOL:g}): {sum(r['agree'] for r in rows)}/{len(rows)}; "
          f"max rel diff SCS {max(r['rel_scs'] for r in rows):.2e}, CVXPY+Clarabel {max(r['rel_clarabel'] for r in rows):.2e}")
    print(f"speed ratio CVXPY+Clarabel wall / Rust solve: median {np.median(ratios):.1f}x, "
          f"min {min(ratios):.1f}x, max {max(ratios):.1f}x (target >= 20x)")
    out = args[0].rsplit("/", 1)[0] + "/crosscheck_results.json"
    json.dump(rows, open(out, "w"), indent=1)
    print(f"wrote {out}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
