#!/usr/bin/env bash
# Installs what a fresh Debian machine lacks to build and test the workspace.
# Idempotent: does nothing when everything is already present. Run as root.
set -euo pipefail

need_pkgs=()
for pkg in libopenblas-dev libgfortran-12-dev pkg-config; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need_pkgs+=("$pkg")
done
if [ "${#need_pkgs[@]}" -gt 0 ]; then
    echo "setup: installing ${need_pkgs[*]} (Clarabel's SDP cones need BLAS/LAPACK)" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null
fi

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found; this workspace needs the machine's Rust toolchain (>= 1.89)" >&2
    exit 1
fi
