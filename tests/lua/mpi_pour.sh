#!/bin/sh
# The MPI decomposition (issue 16): a pour settling in a box, run serially
# and under mpirun -np 1, 2, 3, 4 (decomposed over the ranks), prints the
# same state hashes, contact count, floor force, unbalanced-force ratio and
# kinetic energy, to the bit; a 3D pour and a 2D one of 3,000 disks (several
# chunks of the contact pass, twelve wall blocks). Skipped without mpirun.
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
  for np in 1 2 3 4; do
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
exit $fail
