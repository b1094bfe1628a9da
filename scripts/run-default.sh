#!/usr/bin/env bash
# Installs what is missing, builds (Release) only the program, and runs the default scene: the
# leading Floquet multipliers of the soft-impact oscillator's period-1 orbit (paper parameters).
# Extra arguments go to `delayspec floquet` (e.g. --json).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup-debian.sh"
DELAYSPEC_TARGETS=delayspec_cli "$here/scripts/build.sh" "$here/build"
"$here/build/delayspec" floquet "$here/data/scenes/default.toml" "$@"
