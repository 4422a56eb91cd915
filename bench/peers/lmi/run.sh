#!/usr/bin/env bash
# Cross-check of the lmi beta SDP against CVXPY+SCS and timing against CVXPY+Clarabel.
# Creates a venv in this folder (git-ignored), writes problems to ./out, compares.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install -q "cvxpy==1.9.3" scs clarabel numpy
fi
(cd "$root" && cargo run --release -q -p lmi --example crosscheck_problems -- --out "$here/out")
"$here/.venv/bin/python" "$here/crosscheck.py" "$here/out/problems.json" "$@"
