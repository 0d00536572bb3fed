#!/usr/bin/env bash
# The README's test command: installs what is missing, configures, builds (Release) and runs
# every ctest test (core, grid, Bullet bridge, packaging, README example).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)"
