#!/usr/bin/env bash
# Installs the Debian 12 packages sdfccd needs, only those that are missing (needs root).
# python3-numpy / -pytest / -matplotlib: the Python package (python/), its tests and its example.
set -euo pipefail
PKGS="build-essential cmake pkg-config check libassimp-dev libbullet-dev gnuplot-nox libmeshoptimizer-dev libfcl-dev doxygen clang-14 libfuzzer-14-dev libclang-rt-14-dev valgrind zlib1g-dev python3 python3-numpy python3-pytest python3-matplotlib"
need=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || need="$need $p"; done
if [ -n "$need" ]; then
  echo "installing:$need"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq $need >/dev/null
fi
