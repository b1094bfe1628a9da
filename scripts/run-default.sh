#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs the default scene: the leading Floquet
# multipliers of the soft-impact oscillator's period-1 orbit (paper parameters).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup-debian.sh"
"$here/scripts/build.sh" "$here/build"
"$here/build/delayspec" floquet "$here/data/scenes/default.toml" "$@"
