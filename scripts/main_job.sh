#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, runs the example case file with each
# method, then (when the benchmark program is built) the full evaluation report.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
for m in fwgss certified dcd; do
  echo "== sdfccd_cases --method $m data/cases/example.cases"
  build/samples/sdfccd_cases --method "$m" data/cases/example.cases
done
if [ -x build/samples/sdfccd_bench ]; then
  echo "== full evaluation (progress on stderr)"
  build/samples/sdfccd_bench report build/report
  echo "report written to build/report/README.md"
fi
