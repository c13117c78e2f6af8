#!/usr/bin/env bash
# heron set-up: installs what is missing on a Debian 12 machine (Embree and the tools
# from apt, the pinned Python test environment in .venv), builds heron in release mode
# and renders the default scene to out/default.exr and out/default.png.
#
#   scripts/setup.sh           install, build, render the default scene
#   scripts/setup.sh --deps    install only (used by scripts/test.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

# libllvm19: libLLVM.so.19.1 for the LLVM backend of Dr.Jit (Mitsuba 3's llvm_ad_* variants,
# the reference renderer in .venv). Dr.Jit dlopens the last libLLVM*.so.* it finds in
# /usr/lib/x86_64-linux-gnu, which is libLLVM.so.19.1 once this is installed; with only
# Debian's libllvm15 it picks LLVM 15, which aborts in Dr.Jit's kernels ("LLVM ERROR: Cannot
# select ... fminimum"). To pin it explicitly:
# DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
#
# slurm-wlm (slurmctld, slurmd, the client commands; 22.05) and munge: the single-node
# cluster tests/slurm/cluster.sh starts for tests/python/test_slurm.py, in a temporary
# directory of its own (own munge key and socket, config through SLURM_CONF). Installing
# them starts nothing in a container: their postinst scripts start services through
# invoke-rc.d, which does nothing without a running init (no runlevel) or when a
# policy-rc.d forbids it. Under systemd munge.service starts with Debian's key, which the
# test's cluster does not use, and slurmctld and slurmd do not (their units need
# /etc/slurm/slurm.conf, which nothing writes).
# python3-yaml: the system Python's PyYAML, which reads deploy/k8s/render-job.yaml in
# test_slurm.py (the pinned .venv has no YAML parser).
# chromium and chromium-driver: the real browser (headless) that tests/python/test_viewer.py
# drives through Selenium to test `heron view`'s page (issue 43).
APT_PACKAGES=(libembree-dev embree-tools pkg-config gcc python3-venv python3-pip libllvm19
  slurm-wlm munge python3-yaml chromium chromium-driver)

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing apt packages: ${missing[*]}"
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "${missing[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; install a Rust toolchain (1.80 or newer) and run again" >&2
  exit 1
fi

scripts/setup-python.sh

if [ "${1:-}" = "--deps" ]; then
  exit 0
fi

cargo build --release
mkdir -p out
target/release/heron render scenes/default.toml -o out/default.exr
echo "setup: rendered out/default.exr and out/default.png"
