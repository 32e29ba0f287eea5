#!/bin/sh
# A real reader in CI: ParaView opens a series written by seixo, checks the
# number of points and a field's range, and renders the balls as spheres.
#   paraview.sh SEIXO SOURCE_DIR OUT_DIR
# Skipped (exit 77) when pvbatch or Xvfb is not installed
# (Debian: apt-get install paraview python3-paraview xvfb).
#
# The X server is started here rather than by xvfb-run -a, whose choice of a
# free display races with other servers (CI saw "bad X server connection"):
# with -displayfd the server picks a free display itself and writes its
# number once it accepts connections; -noreset keeps it from resetting when
# its last client closes (a client that connects again during a reset is
# refused: the suite once saw that on all three tries).
set -eu
seixo=$1 src=$2 out=$3
command -v pvbatch > /dev/null 2>&1 || { echo "pvbatch not found: skipped"; exit 77; }
command -v Xvfb > /dev/null 2>&1 || { echo "Xvfb not found: skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/seixo-pv-XXXXXX")
xpid=
trap '[ -n "$xpid" ] && kill "$xpid" 2> /dev/null; rm -rf "$dir"' EXIT
set -- $("$seixo" "$src/paraview_series.lua" "$dir/series.h5")
echo "seixo wrote $1 snapshots of $2 balls, radii $3 .. $4 m"

start_x() {
    rm -f "$dir/display"
    Xvfb -displayfd 3 -nolisten tcp -noreset -screen 0 800x600x24 3> "$dir/display" 2> "$dir/xvfb.log" &
    xpid=$!
    tries=0
    while [ ! -s "$dir/display" ]; do
        kill -0 "$xpid" 2> /dev/null || { cat "$dir/xvfb.log"; echo "paraview.sh: Xvfb did not start"; exit 1; }
        tries=$((tries + 1))
        [ "$tries" -le 300 ] || { echo "paraview.sh: Xvfb gave no display within 30 s"; exit 1; }
        sleep 0.1
    done
    DISPLAY=:$(cat "$dir/display")
    export DISPLAY
}

# One X server per try: a try whose pvbatch cannot reach its server (seen
# when several runs share a loaded machine) is repeated with a new server.
for attempt in 1 2 3; do
    start_x
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
