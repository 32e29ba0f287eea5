# Sourced by scripts/render and tests/io/paraview.sh: start_x DIR starts an
# X server for pvbatch (ParaView renders through X even off screen), sets
# DISPLAY and xpid; the caller kills $xpid when done.
#
# The server picks a free display itself (-displayfd, rather than
# xvfb-run -a, whose choice races with other servers: CI saw "bad X server
# connection") and writes its number once it accepts connections;
# -noreset keeps it from resetting when its last client closes (a client
# that connects again during a reset is refused).
start_x() {
    rm -f "$1/display"
    Xvfb -displayfd 3 -nolisten tcp -noreset -screen 0 1280x1024x24 3> "$1/display" 2> "$1/xvfb.log" &
    xpid=$!
    tries=0
    while [ ! -s "$1/display" ]; do
        kill -0 "$xpid" 2> /dev/null || { cat "$1/xvfb.log"; echo "Xvfb did not start" >&2; exit 1; }
        tries=$((tries + 1))
        [ "$tries" -le 300 ] || { echo "Xvfb gave no display within 30 s" >&2; exit 1; }
        sleep 0.1
    done
    DISPLAY=:$(cat "$1/display")
    export DISPLAY
}
