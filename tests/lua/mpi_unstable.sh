#!/bin/sh
# An instability found on one rank under the MPI decomposition (issue 16):
# a clump pour given a timestep far above the critical one
# (mpi_clumps.lua D STEPS unstable) fails serially with "unstable at step
# N: ..."; under mpirun --oversubscribe -np 1 ... 4 every run must fail
# too, within a time limit (the failing rank used to wait for the others
# in its message's critical estimate, which exchanged the pebbles' sums,
# and the run hung), naming the same step and cause. The estimate itself
# is the failing rank's own (kernels/timestep.c, estimate_dt): left out of
# the comparison. Skipped (77) without mpirun.
#   mpi_unstable.sh SEIXO SCRIPT 'ARGS'
set -u
seixo=$1
script=$2
scene=$3
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
# the instability's step and cause, up to its critical estimate
cause() { grep -o "m:cycle: unstable at step [^(]*" "$1" | sort -u; }
# shellcheck disable=SC2086 # a scene is several arguments
if "$seixo" "$script" $scene >"$dir/serial" 2>"$dir/err"; then
  echo "the serial run did not fail"; cat "$dir/serial"; exit 1
fi
cause "$dir/err" >"$dir/cause"
if [ "$(wc -l <"$dir/cause")" != 1 ]; then
  echo "the serial run did not stop on an instability:"; cat "$dir/err"; exit 1
fi
echo "serial: $(cat "$dir/cause")"
fail=0
for np in $ranks; do
  # shellcheck disable=SC2086
  timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" "$script" $scene >"$dir/out" 2>"$dir/err"
  rc=$?
  if [ $rc = 0 ]; then echo "-np $np did not fail"; fail=1; continue; fi
  if [ $rc = 124 ]; then echo "-np $np hung (killed after 300 s)"; fail=1; continue; fi
  cause "$dir/err" >"$dir/got"
  if cmp -s "$dir/cause" "$dir/got"; then
    echo "-np $np: stopped with the same cause"
  else
    echo "-np $np: another cause or none:"; diff "$dir/cause" "$dir/got"; head -n 20 "$dir/err"; fail=1
  fi
done
exit $fail
