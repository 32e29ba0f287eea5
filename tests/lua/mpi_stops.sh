#!/bin/sh
# A cycle that must stop, under the MPI decomposition (issue 16): the scene
# is run serially and under mpirun --oversubscribe -np 1, 2, 3, 4; every run
# must fail within a time limit (a rank waiting for partners that stopped
# hangs), print what the serial run printed, and report what the serial
# run did, once (not once per rank): the part of its message matched by
# PATTERN (grep -o), which must also contain MUST. Skipped (77) without
# mpirun.
#   mpi_stops.sh SEIXO SCRIPT 'ARGS' PATTERN MUST
# The energy guard (mpi_energy.lua guard): its whole message, the same
# step, gain, scale, fastest ball and critical estimate. An instability
# found on one rank (mpi_clumps.lua ... unstable): its step and cause, up
# to the critical estimate (the ranks' least, made after the other ranks'
# balls went on through the step: dd_agree.c). Errors in the script, in a callback
# and on one rank alone (mpi_fail.lua): the message, and no rank's folder
# of shadows left in TMPDIR. Every message comes from rank 0.
set -u
seixo=$1
script=$2
scene=$3
pattern=$4
must=$5
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
# the message, as many times as it was printed
messages() { grep -o "$pattern" "$1"; }
# the runs' temporary files, where the ranks above 0 keep their shadows of
# the files a script writes: none may be left by a run that failed
export TMPDIR="$dir/tmp"
mkdir -p "$TMPDIR"
# shellcheck disable=SC2086 # a scene is several arguments
if "$seixo" "$script" $scene >"$dir/serial" 2>"$dir/err"; then
  echo "the serial run did not fail"; cat "$dir/serial"; exit 1
fi
messages "$dir/err" >"$dir/message"
if ! grep -q "$must" "$dir/message" || [ "$(wc -l <"$dir/message")" != 1 ]; then
  echo "the serial run did not stop with '$must':"; cat "$dir/err"; exit 1
fi
echo "serial: $(cat "$dir/message")"
fail=0
for np in $ranks; do
  # shellcheck disable=SC2086
  timeout 300 mpirun $root --oversubscribe --tag-output -x TMPDIR -np "$np" "$seixo" "$script" $scene \
    >"$dir/tagged_out" 2>"$dir/tagged_err"
  rc=$?
  # each line tagged with its rank, "[job,rank]<stream>:"
  sed -E 's/^\[[0-9]+,[0-9]+\]<stdout>://' "$dir/tagged_out" >"$dir/out"
  sed -E 's/^\[[0-9]+,[0-9]+\]<stderr>://' "$dir/tagged_err" >"$dir/err"
  if [ $rc = 0 ]; then echo "-np $np did not fail"; fail=1; continue; fi
  if [ $rc = 124 ]; then echo "-np $np hung (killed after 300 s)"; fail=1; continue; fi
  # ranks that fail remove their shadows before the abort, and so do those
  # waiting for a rank that failed alone (rank 0 tells them the job ends);
  # not a rank still computing after rank 0's 5 s wait (scene busy)
  if [ "$scene" != busy ] && ls "$TMPDIR" | grep -q "^seixo-rank"; then
    echo "-np $np: a rank's shadow folder was left: $(ls "$TMPDIR")"; fail=1; rm -rf "$TMPDIR"/seixo-rank*
  fi
  if ! grep -q "^ranks $np$" "$dir/err"; then
    echo "-np $np: the model was not decomposed over $np ranks:"; cat "$dir/err"; fail=1; continue
  fi
  messages "$dir/err" >"$dir/got"
  if cmp -s "$dir/serial" "$dir/out" && cmp -s "$dir/message" "$dir/got"; then
    echo "-np $np: the same output and message"
  else
    echo "-np $np differs:"; diff "$dir/serial" "$dir/out" | head -n 20; diff "$dir/message" "$dir/got"
    head -n 20 "$dir/err"; fail=1
  fi
  # rank 0 reports, whichever rank failed: its own error, one every rank
  # met, or one another rank met alone and told it while rank 0 waited for
  # it (a rank reporting its own after the failing ranks' 5 s wait fails
  # this: the last rank's error alone, an instability found on rank 1)
  if grep -v "^\[[0-9]*,0\]<stderr>:" "$dir/tagged_err" | grep -q -- "$pattern"; then
    echo "-np $np: a rank other than 0 reported:"; grep -- "$pattern" "$dir/tagged_err"; fail=1
  fi
done
exit $fail
