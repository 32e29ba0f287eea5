#!/bin/sh
# Runs a script serially and under mpirun --oversubscribe -np 1, 2, 3, 4
# (decomposed over the ranks, issue 16) with each set of arguments given,
# and fails unless every run prints what the serial run prints, to the
# bit, and says on stderr ("ranks N") that its model ran decomposed over N
# ranks, with no warning printed twice. Skipped (77) without mpirun.
#   mpi_same.sh SEIXO SCRIPT 'ARGS' ['ARGS' ...]
set -u
seixo=$1
script=$2
shift 2
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir, same_as_serial
fail=0
# under the sanitizers only the 1st, 3rd, ... scene: each script's code
# paths memory-checked in half the time (the plain suite runs every scene)
odd=1
for scene in "$@"; do
  if [ -n "$sanitized" ]; then
    odd=$((1 - odd))
    [ "$odd" = 1 ] && { echo "$(basename "$script") '$scene': left to the plain suite"; continue; }
  fi
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
    same_as_serial "-np $np" "$np"
    # seixo's warnings about a shared model come from rank 0 alone
    if sort "$dir/err" | uniq -d | grep "warning:"; then echo "-np $np: a warning came more than once"; fail=1; fi
  done
done
exit $fail
