#!/bin/sh
# A real reader in CI: ParaView opens a series written by seixo, checks the
# number of points and a field's range, and renders the balls as spheres.
#   paraview.sh SEIXO SOURCE_DIR OUT_DIR
# Skipped (exit 77) when pvbatch or xvfb-run is not installed
# (Debian: apt-get install paraview xvfb xauth).
set -eu
seixo=$1 src=$2 out=$3
command -v pvbatch > /dev/null 2>&1 || { echo "pvbatch not found: skipped"; exit 77; }
command -v xvfb-run > /dev/null 2>&1 || { echo "xvfb-run not found: skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/seixo-pv-XXXXXX")
trap 'rm -rf "$dir"' EXIT
set -- $("$seixo" "$src/paraview_series.lua" "$dir/series.h5")
echo "seixo wrote $1 snapshots of $2 balls, radii $3 .. $4 m"
xvfb-run -a pvbatch "$src/paraview_check.py" "$dir/series.xmf" "$1" "$2" "$3" "$4" "$out/paraview_balls.png" 2>&1 |
    grep -v '^ *[0-9]* *0x' > "$dir/pv.log" || true
cat "$dir/pv.log"
grep -q '^paraview_check: OK' "$dir/pv.log"
