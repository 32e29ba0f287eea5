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
if ! command -v mpirun >/dev/null 2>&1; then
  echo "mpirun not found: skipped"
  exit 77
fi
root=
[ "$(id -u)" = 0 ] && root=--allow-run-as-root # Open MPI refuses root without it
# Under AddressSanitizer (scripts/test --sanitize) 3 ranks only (a middle
# rank with a neighbour on each side and two end ranks: the memory checks of
# every code path): the plain suite checks every rank count, and CI's time
# stays short (three MPI tests under ASan).
ranks="1 2 3 4"
if command -v ldd >/dev/null 2>&1 && ldd "$seixo" 2>/dev/null | grep -q libasan; then ranks="3"; fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
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
