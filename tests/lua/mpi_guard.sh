#!/bin/sh
# The energy guard under the MPI decomposition (issue 16): a scene whose
# cycle the guard stops (mpi_energy.lua guard) is run serially and under
# mpirun --oversubscribe -np 1, 2, 3, 4; every run must fail, print what
# the serial run prints, and every rank must stop with the serial run's
# message ("m:cycle: unstable at step ...": the same step, gain, scale,
# fastest ball and critical estimate). Skipped (77) without mpirun.
#   mpi_guard.sh SEIXO SCRIPT 'ARGS'
set -u
seixo=$1
script=$2
scene=$3
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
# the guard's message, once per rank that printed it
messages() { grep -o "m:cycle: unstable at step .*" "$1" | sort -u; }
# shellcheck disable=SC2086 # a scene is several arguments
if "$seixo" "$script" $scene >"$dir/serial" 2>"$dir/err"; then
  echo "the serial run did not fail"; cat "$dir/serial"; exit 1
fi
messages "$dir/err" >"$dir/message"
if ! grep -q "mechanical energy of an unforced system grew" "$dir/message" || [ "$(wc -l <"$dir/message")" != 1 ]; then
  echo "the serial run did not stop on the guard:"; cat "$dir/err"; exit 1
fi
echo "serial: $(cat "$dir/message")"
fail=0
for np in $ranks; do
  # shellcheck disable=SC2086
  if mpirun $root --oversubscribe -np "$np" "$seixo" "$script" $scene >"$dir/out" 2>"$dir/err"; then
    echo "-np $np did not fail"; fail=1; continue
  fi
  if ! grep -q "^ranks $np$" "$dir/err"; then
    echo "-np $np: the model was not decomposed over $np ranks:"; cat "$dir/err"; fail=1; continue
  fi
  messages "$dir/err" >"$dir/got"
  if cmp -s "$dir/serial" "$dir/out" && cmp -s "$dir/message" "$dir/got"; then
    echo "-np $np: the same output and message"
  else
    echo "-np $np differs:"; diff "$dir/serial" "$dir/out" | head -n 20; diff "$dir/message" "$dir/got"; fail=1
  fi
done
exit $fail
