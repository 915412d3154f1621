#!/usr/bin/env bash
# Run check_paraview.py with pvpython on a virtual X display (ParaView draws through GLX; its
# offscreen mode crashes in Debian's build): paraview.sh OUT_DIR [--image FILE.png]
# A virtual display that was not ready ("bad X server connection", seen when tests start X
# servers at once or on a loaded machine) is retried, up to five times with a growing pause; any
# other failure is the check's verdict.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
for tool in pvpython xvfb-run; do
  command -v "$tool" >/dev/null || { echo "paraview.sh: $tool is missing (./fsi test installs it)" >&2; exit 1; }
done
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for attempt in 1 2 3 4 5; do
  xvfb-run -a -s "-screen 0 1280x1024x24" pvpython "$here/check_paraview.py" "$@" >"$log" 2>&1
  rc=$?
  cat "$log"
  grep -q "bad X server connection" "$log" || exit $rc
  echo "paraview.sh: the virtual display was not ready (attempt $attempt); again" >&2
  sleep "$attempt"
done
exit $rc
