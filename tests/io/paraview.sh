#!/bin/sh
# A real reader in CI: ParaView opens a series written by seixo, checks the
# number of points and a field's range, and renders the balls as spheres.
#   paraview.sh SEIXO SOURCE_DIR OUT_DIR
# Skipped (exit 77) when pvbatch or Xvfb is not installed
# (Debian: apt-get install paraview python3-paraview xvfb).
#
# The X server is started by scripts/xvfb.sh's start_x.
set -eu
seixo=$1 src=$2 out=$3
command -v pvbatch > /dev/null 2>&1 || { echo "pvbatch not found: skipped"; exit 77; }
command -v Xvfb > /dev/null 2>&1 || { echo "Xvfb not found: skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/seixo-pv-XXXXXX")
xpid=
trap '[ -n "$xpid" ] && kill "$xpid" 2> /dev/null; rm -rf "$dir"' EXIT
set -- $("$seixo" "$src/paraview_series.lua" "$dir/series.h5")
echo "seixo wrote $1 snapshots of $2 balls, radii $3 .. $4 m"
. "$src/../../scripts/xvfb.sh"

# One X server per try: a try whose pvbatch cannot reach its server (seen
# when several runs share a loaded machine) is repeated with a new server.
for attempt in 1 2 3; do
    start_x "$dir"
    echo "Xvfb on display $DISPLAY (try $attempt)"
    pvbatch "$src/paraview_check.py" "$dir/series.xmf" "$1" "$2" "$3" "$4" "$out/paraview_balls.png" 2>&1 |
        grep -v '^ *[0-9]* *0x' > "$dir/pv.log" || true
    kill "$xpid" 2> /dev/null || true
    wait "$xpid" 2> /dev/null || true
    xpid=
    grep -q 'bad X server connection' "$dir/pv.log" || break
    echo "pvbatch could not connect to display $DISPLAY; the server said:"
    cat "$dir/xvfb.log"
    sleep 2
done
cat "$dir/pv.log"
grep -q '^paraview_check: OK' "$dir/pv.log"
