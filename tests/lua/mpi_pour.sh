#!/bin/sh
# The MPI decomposition (issue 16): a pour settling in a box, run serially
# and under mpirun -np 1, 2, 3, 4 (decomposed over the ranks), prints the
# same state hashes, contact count, floor force, unbalanced-force ratio and
# kinetic energy, to the bit; a 3D pour and a 2D one of 3,000 disks (several
# chunks of the contact pass, twelve wall blocks). Then a pour saved with 3
# ranks and loaded with 2 ranks, and serially, ends as the serial run does
# (and so do a bonded specimen and a bonded periodic cell breaking bonds
# across the save);
# and a servo-controlled lid moves alike with 2 and 3 ranks; an output
# series written with 2 and 3 ranks is the serial one (mpi_output.lua); a
# long cycle's progress lines come from rank 0 (mpi_progress.lua), and so
# does a live plot (mpi_plot.lua); ranks whose models differ are stopped
# with the cause, and so are ranks of which some moved a wall after a cycle
# left the balls scattered (mpi_diverge.lua).
# Skipped without mpirun. The pours run through mpi_same.sh (which
# checks 3 ranks only under AddressSanitizer).
#   mpi_pour.sh SEIXO mpi_pour.lua
set -u
seixo=$1
script=$2
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir
fail=0
sh "$(dirname "$0")/mpi_same.sh" "$seixo" "$script" "600 6000 3" "3000 4000 2" || fail=1
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
# a file saved with 3 ranks, loaded with 2 (and serially), continues bit-for-bit:
# a pour, a bonded specimen and a bonded periodic cell breaking bonds before
# and after the save
# the progress line under MPI: rank 0's chunks on every rank, its lines only
# (steps strictly increasing: no line repeated by another rank), the same bits
progress=$(dirname "$script")/mpi_progress.lua
"$seixo" "$progress" >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
if mpirun $root --oversubscribe -np 3 "$seixo" "$progress" >"$dir/out" 2>"$dir/err" &&
   grep -q "^ranks 3$" "$dir/err" && cmp -s "$dir/serial" "$dir/out"; then
  lines=$(grep -c "^seixo: m:cycle: step " "$dir/err")
  if [ "$lines" -ge 2 ] && grep "^seixo: m:cycle: step " "$dir/err" | awk '{ if ($4 <= last) exit 1; last = $4 }'; then
    echo "progress, -np 3: $lines lines from one rank, identical"
  else
    echo "progress, -np 3: $lines lines, or a step repeated:"; cat "$dir/err"; fail=1
  fi
else
  echo "progress, -np 3 differs or failed:"; cat "$dir/out" "$dir/err"; fail=1
fi
# ranks whose models differ by one bit of one velocity: stopped with the cause
diverge=$(dirname "$script")/mpi_diverge.lua
if mpirun $root --oversubscribe -np 3 "$seixo" "$diverge" >"$dir/out" 2>"$dir/err"; then
  echo "diverging ranks, -np 3: not stopped"; cat "$dir/out"; fail=1
elif grep -q "m:cycle: the model differs between the 3 ranks" "$dir/err" && ! grep -q "not stopped" "$dir/out"; then
  echo "diverging ranks, -np 3: stopped, naming the cause"
else
  echo "diverging ranks, -np 3: failed without naming the cause:"; cat "$dir/out" "$dir/err"; fail=1
fi
# a wall moved on the ranks above 0 alone, after a cycle that left the balls scattered
if timeout 120 mpirun $root --oversubscribe -np 3 "$seixo" "$diverge" wall >"$dir/out" 2>"$dir/err"; then
  echo "a wall moved on some ranks, -np 3: not stopped"; cat "$dir/out"; fail=1
elif grep -q "m:cycle: the walls or settings differ between the 3 ranks" "$dir/err" && ! grep -q "not stopped" "$dir/out"; then
  echo "a wall moved on some ranks, -np 3: stopped, naming the cause"
else
  echo "a wall moved on some ranks, -np 3: failed without naming the cause (or hung):"; cat "$dir/out" "$dir/err"; fail=1
fi
# a live plot on gnuplot's dumb terminal (to standard output): drawn by rank 0 alone
plotter=$(dirname "$script")/mpi_plot.lua
if command -v gnuplot >/dev/null 2>&1; then
  "$seixo" "$plotter" >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
  if mpirun $root --oversubscribe -np 3 "$seixo" "$plotter" >"$dir/out" 2>"$dir/err" &&
     grep -q "^ranks 3$" "$dir/err" && cmp -s "$dir/serial" "$dir/out"; then
    echo "live plot, -np 3: drawn once, identical ($(wc -l <"$dir/out") lines)"
  else
    echo "live plot, -np 3 differs or failed:"; diff "$dir/serial" "$dir/out" | head -n 20; cat "$dir/err"; fail=1
  fi
else
  echo "gnuplot not found: the live plot under MPI not checked"
fi
restart=$(dirname "$script")/mpi_restart.lua
for kind in pour bonded periodic; do
  # shellcheck disable=SC2086
  "$seixo" "$restart" save "$dir/serial.h5" $kind >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
  echo "restart ($kind), serial:"; cat "$dir/serial"
  # shellcheck disable=SC2086
  mpirun $root --oversubscribe -np 3 "$seixo" "$restart" save "$dir/three.h5" $kind >"$dir/saved" 2>"$dir/err" &&
    grep -q "^ranks 3$" "$dir/err" || { echo "the save with 3 ranks failed:"; cat "$dir/err"; exit 1; }
  # shellcheck disable=SC2086
  mpirun $root --oversubscribe -np 2 "$seixo" "$restart" load "$dir/three.h5" >"$dir/loaded" 2>"$dir/err" &&
    grep -q "^ranks 2$" "$dir/err" || { echo "the load with 2 ranks failed:"; cat "$dir/err"; exit 1; }
  "$seixo" "$restart" load "$dir/three.h5" >"$dir/loaded1" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
  for run in saved loaded loaded1; do
    if cmp -s "$dir/serial" "$dir/$run"; then
      echo "restart ($kind), $run: identical"
    else
      echo "restart ($kind), $run differs:"; diff "$dir/serial" "$dir/$run"; fail=1
    fi
  done
done
# an output series written by rank 0 for all ranks: the same file, to the
# bit, as the serial run's (but its creation time), the same answers and
# errors on every rank
output=$(dirname "$script")/mpi_output.lua
if command -v h5dump >/dev/null 2>&1; then
  dump() { h5dump -m %.17g "$1" | sed -e 1d -e '/^ *(0): "[0-9-]*T[0-9:]*Z"$/d'; }
  "$seixo" "$output" "$dir/serial_series.h5" >"$dir/serial" 2>"$dir/err" || { cat "$dir/err"; exit 1; }
  echo "series, serial:"; cat "$dir/serial"
  dump "$dir/serial_series.h5" >"$dir/serial_dump"
  for np in 2 3; do
    # shellcheck disable=SC2086
    if mpirun $root --oversubscribe -np "$np" "$seixo" "$output" "$dir/series$np.h5" >"$dir/out" 2>"$dir/err" &&
       grep -q "^ranks $np$" "$dir/err" && cmp -s "$dir/serial" "$dir/out" &&
       dump "$dir/series$np.h5" >"$dir/dump" && cmp -s "$dir/serial_dump" "$dir/dump"; then
      echo "series, -np $np: identical (answers and file)"
    else
      echo "series, -np $np differs or failed:"; cat "$dir/out" "$dir/err"; diff "$dir/serial_dump" "$dir/dump" | head -20; fail=1
    fi
  done
else
  echo "h5dump not found: the series under MPI not checked"
fi
exit $fail
