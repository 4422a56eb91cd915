#!/usr/bin/env python3
"""Per-class table of `bench_one` outputs (issue 27's acceptance): named (top-1), main
parameter within 15 %, within the reported 2 sigma, and the slowest case.

Usage: python3 scripts/discovery-bench-table.py OUT1.txt [OUT2.txt ...]
(each OUT the stdout of `cargo run --release -p discovery --example bench_one CASES SEED PROFILE CLASSES`).
"""
import re
import sys
from collections import defaultdict

LINE = re.compile(r"^\s*(\w+) -> (\S+)\s.*?perr (Some\(([-\d.e+]+)\)|None).*?true (Some\(([-\d.e+]+)\)|None) "
                  r"est (Some\(([-\d.e+]+)\)|None) sd (Some\(([-\d.e+]+)\)|None) (?:sdstat (?:Some\([-\d.e+]+\)|None) )?([\d.]+)s ")


def main(paths):
    rows = defaultdict(lambda: {"n": 0, "named": 0, "p15": 0, "np": 0, "z2": 0, "nz": 0, "max_s": 0.0})
    for path in paths:
        for line in open(path):
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


if __name__ == "__main__":
    main(sys.argv[1:])
