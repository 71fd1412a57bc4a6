#!/usr/bin/env bash
# Set everything up, build, and run the whole test suite (unit, physics, regression, CLI).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh build
ctest --test-dir build --output-on-failure -j"$(nproc)"
