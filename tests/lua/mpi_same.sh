#!/bin/sh
# Runs a script serially and under mpirun --oversubscribe -np 1, 2, 3, 4
# (decomposed over the ranks, issue 16) with each set of arguments given,
# and fails unless every run prints what the serial run prints, to the
# bit, and says on stderr ("ranks N") that its model ran decomposed over N
# ranks. Skipped (77) without mpirun.
#   mpi_same.sh SEIXO SCRIPT 'ARGS' ['ARGS' ...]
set -u
seixo=$1
script=$2
shift 2
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
fail=0
for scene in "$@"; do
  # shellcheck disable=SC2086 # a scene is several arguments
  if ! "$seixo" "$script" $scene >"$dir/serial" 2>"$dir/err"; then
    echo "serial run of '$scene' failed:"; cat "$dir/err"; exit 1
  fi
  grep -q "^ranks 1$" "$dir/err" || { echo "the serial run is not serial"; cat "$dir/err"; exit 1; }
  echo "$(basename "$script") '$scene', serial:"; head -n 20 "$dir/serial"
  for np in $ranks; do
    # shellcheck disable=SC2086
    if ! mpirun $root --oversubscribe -np "$np" "$seixo" "$script" $scene >"$dir/out" 2>"$dir/err"; then
      echo "-np $np failed:"; cat "$dir/err"; fail=1; continue
    fi
    if ! grep -q "^ranks $np$" "$dir/err"; then
      echo "-np $np: the model was not decomposed over $np ranks:"; cat "$dir/err"; fail=1; continue
    fi
    if cmp -s "$dir/serial" "$dir/out"; then
      echo "-np $np: identical ($(wc -l <"$dir/out") lines)"
    else
      echo "-np $np differs:"; diff "$dir/serial" "$dir/out" | head -n 40; fail=1
    fi
  done
done
exit $fail
