#!/bin/sh
# A SIGTERM that ends a rank under mpirun (mpi_term.lua) must leave no
# seixo-rank* folder in $TMPDIR, where the ranks above 0 keep their private
# copies of the script's files: they piled up at every job mpirun or a
# scheduler ended. Skipped (77) without mpirun.
#   mpi_term.sh SEIXO SCRIPT
set -u
seixo=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
script=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, dir
mkdir -p "$dir/tmp" && cd "$dir" || exit 1
TMPDIR="$dir/tmp" timeout 120 mpirun $root --oversubscribe -np 2 -x TMPDIR "$seixo" "$script" >"$dir/out" 2>"$dir/err"
rc=$?
if [ $rc = 124 ]; then echo "hung"; cat "$dir/err"; exit 1; fi
if [ $rc = 0 ] || grep -q "not ended" "$dir/out"; then echo "the job did not end on the signal"; exit 1; fi
if ! grep -q "copies' folders before the signal: 1" "$dir/err"; then
  echo "the last rank had no folder of copies before the signal:"; cat "$dir/err"; exit 1
fi
left=$(ls "$dir/tmp" | grep -c seixo-rank)
if [ "$left" != 0 ]; then echo "$left folder(s) of copies left:"; ls -R "$dir/tmp"; exit 1; fi
echo "ended by the signal (rc $rc), no folder of copies left"
