#!/bin/sh
# scripts/render draws a series with ParaView headless: a series whose
# bonds break (tests/io/render_series.lua) is written and rendered from its
# own directory by bare file names (the name ParaView's Xdmf3 readers fail
# on), by scripts/render and by `seixo render`, and the PNG shows the balls
# and the crack map; ParaView's XDMF Reader shows the blocks by name
# (pv_names.py), by a bare name and by a relative path.
#   render.sh SEIXO SOURCE_DIR
# Skipped (exit 77) when pvbatch or Xvfb is not installed.
set -eu
seixo=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") src=$(cd "$2" && pwd)
command -v pvbatch > /dev/null 2>&1 || { echo "pvbatch not found: skipped"; exit 77; }
command -v Xvfb > /dev/null 2>&1 || { echo "Xvfb not found: skipped"; exit 77; }
command -v pvpython > /dev/null 2>&1 || { echo "pvpython not found: skipped"; exit 77; }
dir=$(mktemp -d "${TMPDIR:-/tmp}/seixo-render-test-XXXXXX")
trap 'rm -rf "$dir"' EXIT
cd "$dir"
set -- $("$seixo" "$src/render_series.lua" cracks.h5)
echo "seixo wrote $1 snapshots of $2 balls with $3 cracks"
[ "$3" -gt 0 ] || { echo "the scene broke no bond"; exit 1; }
grep -q '<Grid Name="cracks"' cracks.xmf || { echo "no cracks block in cracks.xmf"; exit 1; }
grep -q '>cracks.h5:/snapshots/' cracks.xmf || { echo "cracks.xmf does not name cracks.h5 beside it"; exit 1; }
out=$(env -u DISPLAY "$src/../../scripts/render" cracks.xmf cracks.png)
echo "$out"
echo "$out" | grep -q "(snapshot $1 of $1, t = [0-9.e-]* s): $2 balls, 0 wall cells, [0-9]* bonds, $3 cracks$" ||
    { echo "render.sh: not the counts of the last snapshot"; exit 1; }
file cracks.png | grep -q 'PNG image data, 1024 x 768' || { file cracks.png; exit 1; }
size=$(wc -c < cracks.png)
[ "$size" -gt 10000 ] || { echo "cracks.png has only $size bytes"; exit 1; }
# the same through the seixo executable's subcommand
out=$(env -u DISPLAY "$seixo" render cracks.xmf again.png 0)
echo "$out"
echo "$out" | grep -q "(snapshot 1 of $1, t = 0 s): $2 balls, 0 wall cells, [0-9]* bonds, 0 cracks$" ||
    { echo "render.sh: seixo render: not the counts of the first snapshot"; exit 1; }
file again.png | grep -q 'PNG image data, 1024 x 768' || { file again.png; exit 1; }
if "$seixo" render 2> err.txt; then echo "seixo render without arguments succeeded"; exit 1; fi
grep -q "^usage: seixo render SERIES.xmf OUT.png \[SNAPSHOT\]" err.txt || { cat err.txt; exit 1; }
# ParaView's XDMF Reader shows the blocks by name, from the series' directory
# by a bare name and from another directory by a relative path
pvpython "$src/pv_names.py" cracks.xmf "$1" balls contacts bonds cracks > names.txt 2>&1 || true
cat names.txt
grep -q '^pv_names: OK' names.txt || exit 1
mkdir sub
(cd sub && pvpython "$src/pv_names.py" ../cracks.xmf "$1" balls contacts bonds cracks > ../names.txt 2>&1) || true
grep -q '^pv_names: OK' names.txt || { cat names.txt; exit 1; }
# a snapshot out of the series is refused, naming the count
if env -u DISPLAY "$src/../../scripts/render" cracks.xmf x.png 99 2> err.txt; then echo "snapshot 99 accepted"; exit 1; fi
grep -q "the series has $1 snapshots, no snapshot 99" err.txt || { cat err.txt; exit 1; }
echo "render.sh: OK"
