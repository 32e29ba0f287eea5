#!/bin/sh
# Collective calls made by some ranks only (mpi_calls.lua): each scene runs
# serially to its end, and under mpirun --oversubscribe -np 2, 3, 4 must
# fail within a time limit (never hang) with the message naming the
# ranks' calls printed once. Skipped (77) without mpirun.
#   mpi_calls.sh SEIXO SCRIPT SCENE CALL [MESSAGE]
# MESSAGE, the message's beginning before CALL (a pattern), is by default
# that of two calls that differ.
set -u
seixo=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") # absolute: the runs are in $dir
script=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
scene=$3
call=$4
message=${5:-"the ranks made different calls: rank 0 is in "}
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
cd "$dir" || exit 1 # the scenes' files go with it
if ! "$seixo" "$script" "$scene" >"$dir/serial" 2>"$dir/err" || ! grep -q "^ended $scene$" "$dir/serial"; then
  echo "the serial run of '$scene' did not end:"; cat "$dir/serial" "$dir/err"; exit 1
fi
fail=0
for np in $ranks; do
  [ "$np" -lt 2 ] && continue
  timeout 120 mpirun $root --oversubscribe -np "$np" "$seixo" "$script" "$scene" >"$dir/out" 2>"$dir/err"
  rc=$?
  if [ $rc = 0 ]; then echo "$scene, -np $np did not fail"; cat "$dir/out"; fail=1; continue; fi
  if [ $rc = 124 ]; then echo "$scene, -np $np hung (killed after 120 s)"; fail=1; continue; fi
  said=$(grep -c "$message.*$call" "$dir/err")
  if [ "$said" = 1 ] && [ -z "${5:-}" ] && ! grep -q "in a loop over pairs() of a table with string keys" "$dir/err"; then
    echo "$scene, -np $np: the message does not name pairs()' order among the causes:"; cat "$dir/err"; fail=1
  elif [ "$said" = 1 ]; then
    echo "$scene, -np $np: stopped, said once: $(grep -o "$message[^(]*" "$dir/err")"
  else
    echo "$scene, -np $np: the message not once ($said):"; cat "$dir/err"; fail=1
  fi
done
exit $fail
