#!/usr/bin/env bash
# Run check_paraview.py with pvpython on a virtual X display (ParaView draws through GLX; its
# offscreen mode crashes in Debian's build): paraview.sh OUT_DIR [--image FILE.png]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
for tool in pvpython xvfb-run; do
  command -v "$tool" >/dev/null || { echo "paraview.sh: $tool is missing (./fsi test installs it)" >&2; exit 1; }
done
exec xvfb-run -a -s "-screen 0 1280x1024x24" pvpython "$here/check_paraview.py" "$@"
