#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, runs the example case file with each
# method, then the full evaluation report (accuracy tables, chart, scaling, peers).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
for m in fwgss certified dcd; do
  echo "== sdfccd_cases --method $m data/cases/example.cases"
  build/samples/sdfccd_cases --method "$m" data/cases/example.cases
done
echo "== full evaluation: scripts/bench_report.sh build/report (each sdfccd_bench experiment to CSV, then sdfccd_bench_report)"
# Reuse the committed data set and certified ground truth (recomputing them adds ~4 minutes).
mkdir -p build/report
cp -r samples/report/dataset build/report/
bash scripts/bench_report.sh build/report --build build
echo "report: build/report/report.md (chart: build/report/speed_accuracy.png); the committed full run is samples/report/report.md"

# The Python package (README "Python"): build/python holds it; the first python3 with numpy imports it.
py=python3
python3 -c "import numpy" 2>/dev/null || py=/usr/bin/python3
echo "== python: PYTHONPATH=\$PWD/build/python python3 -c \"import sdfccd; print(sdfccd.__version__)\""
PYTHONPATH="$PWD/build/python" "$py" -c "import sdfccd; print(sdfccd.__version__)"
