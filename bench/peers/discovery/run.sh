#!/usr/bin/env bash
# Peer cross-check of `load_friction` on the BAM XL330 logs (issue 28): an independent NumPy
# model in the form of the BAM actuator models (M1: Coulomb-viscous, M3: load-dependent),
# fitted with SciPy on one, two and three logs; compare with `moreau diagnose --data ...`
# (BENCHMARKS.md, "load_friction on the BAM logs"). About 4 minutes on 2 cores.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet numpy scipy
fi
"$here/.venv/bin/python" "$here/bam_m3.py" "$root/data/bam-servo"
