#!/usr/bin/env python3
"""Per-class table of `bench_one` outputs (issue 27's acceptance): named (top-1), main
parameter within 15 %, within the reported 2 sigma, and the slowest case; with `BENCH_NEXT=1`
outputs, a second table: how the returned models predict each machine's next experiment.

Usage: python3 scripts/discovery-bench-table.py OUT1.txt [OUT2.txt ...]
(each OUT the stdout of `cargo run --release -p discovery --example bench_one CASES SEED PROFILE CLASSES`).
"""
import re
import sys
from collections import defaultdict

LINE = re.compile(r"^\s*(\w+) -> (\S+)\s.*?perr (Some\(([-\d.e+]+)\)|None).*?true (Some\(([-\d.e+]+)\)|None) "
                  r"est (Some\(([-\d.e+]+)\)|None) sd (Some\(([-\d.e+]+)\)|None) (?:sdstat (?:Some\([-\d.e+]+\)|None) )?([\d.]+)s ")

NEXT = re.compile(r"^\s*next experiment \((.*?)\): RMSE nominal ([-\d.e+naNinf]+), returned ([-\d.e+naNinf]+), "
                  r"noise floor ([-\d.e+naNinf]+);")
AT_FLOOR = 1.1  # bench::NEXT_AT_FLOOR: within a tenth of the noise floor

def main(paths):
    rows = defaultdict(lambda: {"n": 0, "named": 0, "p15": 0, "np": 0, "z2": 0, "nz": 0, "max_s": 0.0})
    nexts = defaultdict(list)
    for path in paths:
        cls = None
        for line in open(path):
            n = NEXT.match(line)
            if n and cls is not None:
                nexts[cls].append(tuple(float(n.group(i)) for i in (2, 3, 4)))
                continue
            m = LINE.match(line)
            if not m:
                continue
            cls, pred = m.group(1), m.group(2)
            r = rows[cls]
            r["n"] += 1
            r["named"] += pred.split("+")[0] == cls  # top-1: the first effect selected, as the benchmark counts
            r["max_s"] = max(r["max_s"], float(m.group(11)))
            if m.group(4) is not None:
                r["np"] += 1
                r["p15"] += float(m.group(4)) <= 0.15
            if None not in (m.group(6), m.group(8), m.group(10)):
                t, e, sd = float(m.group(6)), float(m.group(8)), float(m.group(10))
                r["nz"] += 1
                r["z2"] += abs(e - t) <= 2.0 * sd
    if not rows:
        # a changed line format must not read as an empty benchmark
        sys.exit(f"discovery-bench-table: no case line of bench_one in {', '.join(paths)} (has its format changed?)")
    tot = defaultdict(int)
    print("| class | cases | named | within 15 % | within 2 sigma | slowest (s) |")
    print("|---|---|---|---|---|---|")
    for cls, r in rows.items():
        print(f"| {cls} | {r['n']} | {r['named']} | {r['p15']}/{r['np']} | {r['z2']}/{r['nz']} | {r['max_s']:.1f} |")
        for k in ("n", "named", "p15", "np", "z2", "nz"):
            tot[k] += r[k]
    eff = {k: sum(r[k] for c, r in rows.items() if c != "none") for k in ("n", "named")}
    print(f"| all | {tot['n']} | {tot['named']} ({100 * tot['named'] / max(tot['n'], 1):.1f} %) "
          f"| {tot['p15']}/{tot['np']} ({100 * tot['p15'] / max(tot['np'], 1):.1f} %) "
          f"| {tot['z2']}/{tot['nz']} ({100 * tot['z2'] / max(tot['nz'], 1):.1f} %) | |")
    print(f"(effect classes alone: named {eff['named']}/{eff['n']})")
    if nexts:
        next_table(nexts)


def next_table(nexts):
    """Per class: the returned model's prediction of the next experiment within AT_FLOOR of
    the noise floor, worse than the nominal's, and the median RMSE over the floor of each."""
    def median(v):
        v = sorted(v)
        return v[len(v) // 2]
    print()
    print("| class | cases | returned model at the noise floor | worse than the nominal "
          "| RMSE / floor, nominal (median) | RMSE / floor, returned (median) |")
    print("|---|---|---|---|---|---|")
    allv = []
    for cls, v in nexts.items():
        allv += v
        print(f"| {cls} | {len(v)} | {sum(f <= AT_FLOOR * t for _, f, t in v)} | {sum(f > nm for nm, f, _ in v)} "
              f"| {median([nm / t for nm, _, t in v]):.2f} | {median([f / t for _, f, t in v]):.2f} |")
    print(f"| all | {len(allv)} | {sum(f <= AT_FLOOR * t for _, f, t in allv)} | {sum(f > nm for nm, f, _ in allv)} "
          f"| {median([nm / t for nm, _, t in allv]):.2f} | {median([f / t for _, f, t in allv]):.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
