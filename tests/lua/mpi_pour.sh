#!/bin/sh
# The MPI decomposition (issue 16): a pour settling in a box, run serially
# and under mpirun -np 1, 2, 3, 4 (decomposed over the ranks), prints the
# same state hashes, contact count, floor force, unbalanced-force ratio and
# kinetic energy, to the bit; a 3D pour and a 2D one of 3,000 disks (several
# chunks of the contact pass, twelve wall blocks). Then a pour saved with 3
# ranks and loaded with 2 ranks, and serially, ends as the serial run does;
# and a servo-controlled lid moves alike with 2 and 3 ranks.
# Skipped without mpirun.
#   mpi_pour.sh SEIXO mpi_pour.lua
set -u
seixo=$1
script=$2
if ! command -v mpirun >/dev/null 2>&1; then
  echo "mpirun not found: skipped"
  exit 77
fi
root=
[ "$(id -u)" = 0 ] && root=--allow-run-as-root # Open MPI refuses root without it
# Under AddressSanitizer (scripts/test --sanitize) the pours run on 2 and 3
# ranks only (one even and one odd cut, the memory checks of every code
# path): the plain suite checks every rank count, and CI's time stays short.
ranks="1 2 3 4"
if command -v ldd >/dev/null 2>&1 && ldd "$seixo" 2>/dev/null | grep -q libasan; then ranks="2 3"; fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
for scene in "600 6000 3" "3000 4000 2"; do
  # shellcheck disable=SC2086 # the scene is three arguments
  if ! "$seixo" "$script" $scene >"$dir/serial" 2>"$dir/err"; then
    echo "serial run of '$scene' failed:"; cat "$dir/err"; exit 1
  fi
  grep -q "^ranks 1$" "$dir/err" || { echo "the serial run is not serial"; exit 1; }
  [ "$(grep -c '^hash ' "$dir/serial")" = 1 ] || { echo "no hash from the serial run"; cat "$dir/serial"; exit 1; }
  echo "scene '$scene', serial:"; cat "$dir/serial"
  for np in $ranks; do
    # shellcheck disable=SC2086
    if ! mpirun $root --oversubscribe -np "$np" "$seixo" "$script" $scene >"$dir/out" 2>"$dir/err"; then
      echo "-np $np failed:"; cat "$dir/err"; fail=1; continue
    fi
    want=$np; [ "$np" = 1 ] && want=1
    if ! grep -q "^ranks $want$" "$dir/err"; then
      echo "-np $np: the model was not decomposed over $want ranks:"; cat "$dir/err"; fail=1; continue
    fi
    if cmp -s "$dir/serial" "$dir/out"; then
      echo "-np $np: identical"
    else
      echo "-np $np differs:"; diff "$dir/serial" "$dir/out"; fail=1
    fi
  done
done
# a servo-controlled lid (a wall force summed over the ranks' blocks drives it)
servo=$(dirname "$script")/mpi_servo.lua
"$seixo" "$servo" >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
echo "servo, serial:"; cat "$dir/serial"
for np in 2 3; do
  # shellcheck disable=SC2086
  if mpirun $root --oversubscribe -np "$np" "$seixo" "$servo" >"$dir/out" 2>"$dir/err" &&
     grep -q "^ranks $np$" "$dir/err" && cmp -s "$dir/serial" "$dir/out"; then
    echo "servo, -np $np: identical"
  else
    echo "servo, -np $np differs or failed:"; cat "$dir/out" "$dir/err"; fail=1
  fi
done
# a file saved with 3 ranks, loaded with 2 (and serially), continues bit-for-bit
restart=$(dirname "$script")/mpi_restart.lua
"$seixo" "$restart" save "$dir/serial.h5" >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
echo "restart, serial:"; cat "$dir/serial"
# shellcheck disable=SC2086
mpirun $root --oversubscribe -np 3 "$seixo" "$restart" save "$dir/three.h5" >"$dir/saved" 2>"$dir/err" &&
  grep -q "^ranks 3$" "$dir/err" || { echo "the save with 3 ranks failed:"; cat "$dir/err"; exit 1; }
# shellcheck disable=SC2086
mpirun $root --oversubscribe -np 2 "$seixo" "$restart" load "$dir/three.h5" >"$dir/loaded" 2>"$dir/err" &&
  grep -q "^ranks 2$" "$dir/err" || { echo "the load with 2 ranks failed:"; cat "$dir/err"; exit 1; }
"$seixo" "$restart" load "$dir/three.h5" >"$dir/loaded1" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
for run in saved loaded loaded1; do
  if cmp -s "$dir/serial" "$dir/$run"; then
    echo "restart, $run: identical"
  else
    echo "restart, $run differs:"; diff "$dir/serial" "$dir/$run"; fail=1
  fi
done
exit $fail
