#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Configures and builds viscera. Usage: deploy/build.sh [BUILD_DIR] [extra cmake args...]
# Default BUILD_DIR is build/ at the repository root.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${1:-$ROOT/build}"
shift || true
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
