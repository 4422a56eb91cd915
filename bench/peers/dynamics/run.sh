#!/usr/bin/env bash
# Peer harness of the dynamics crate: NumPy catching-up (loop and 1,000-trajectory vectorised
# ensemble, peer.py) vs the Rust single path and the SIMD ensemble integrator
# (dynamics::integrators::ensemble, examples/peer_rust.rs) on the same problem (worked example,
# h = 1e-3, same initial states); prints steps/s and ratios. Rust runs on one core; NumPy is
# left free to use its BLAS threads (the ensemble's x @ Phi.T), as before.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
if [ ! -x "$here/.venv/bin/python" ]; then
  python3 -m venv "$here/.venv"
  "$here/.venv/bin/pip" install --quiet numpy scipy
fi
py=$("$here/.venv/bin/python" "$here/peer.py" 200000 10000)
rs=$(cd "$root" && cargo run --quiet --release -p dynamics --example peer_rust -- 50000000 1000 10000 9)
echo "$py"; echo "$rs"
ns=$(echo "$py" | awk '/numpy_single/{print $2}'); ne=$(echo "$py" | awk '/numpy_ensemble/{print $2}')
rsng=$(echo "$rs" | awk '/^rust_single/{print $2}'); rens=$(echo "$rs" | awk '/^rust_ensemble /{print $2}')
rloop=$(echo "$rs" | awk '/^rust_ensemble_loop/{print $2}')
python3 -c "print(f'ratio single   rust/numpy = {float(\"$rsng\")/float(\"$ns\"):.1f}'); print(f'ratio ensemble rust/numpy = {float(\"$rens\")/float(\"$ne\"):.1f} (SIMD ensemble; single path in a loop: {float(\"$rloop\")/float(\"$ne\"):.1f})')"
