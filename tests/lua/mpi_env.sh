# Sourced by the MPI test scripts (mpi_same.sh, mpi_stops.sh, mpi_pour.sh)
# once $seixo is set: exits 77 (skipped) without mpirun; sets root (Open
# MPI refuses root without --allow-run-as-root), ranks and dir (a temporary
# directory removed at exit). Under AddressSanitizer (scripts/test
# --sanitize) ranks is 3 only (a middle rank with a neighbour on each side
# and two end ranks: the memory checks of every code path) and sanitized
# is 1 (mpi_same.sh then runs every other scene): the plain suite checks
# every rank count and scene, and CI's time stays short.
if ! command -v mpirun >/dev/null 2>&1; then
  echo "mpirun not found: skipped"
  exit 77
fi
root=
[ "$(id -u)" = 0 ] && root=--allow-run-as-root
ranks="1 2 3 4"
# A rank waiting for a message polls; with more ranks than cores (4 here on
# CI's 2) and the suite's other tests beside them, a poller that keeps its
# core starves the rank it waits for. Yielding costs a waiting rank nothing.
export OMPI_MCA_mpi_yield_when_idle=1
# The same for OpenMP's threads (mpi_threads.lua: 2 a rank): spinning, 4
# ranks of 2 on 2 cores ran a scene 100 times slower than passive.
export OMP_WAIT_POLICY=passive
sanitized=
if command -v ldd >/dev/null 2>&1 && ldd "$seixo" 2>/dev/null | grep -q libasan; then ranks="3"; sanitized=1; fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# After a run with $2 ranks (its output in $dir/out, stderr in $dir/err):
# fail=1, saying why, unless it said "ranks $2" (its model ran decomposed)
# and printed what the serial run printed ($dir/serial). $1 names the run.
same_as_serial() {
  if ! grep -q "^ranks $2$" "$dir/err"; then
    echo "$1: the model was not decomposed over $2 ranks:"; cat "$dir/err"; fail=1; return
  fi
  if cmp -s "$dir/serial" "$dir/out"; then
    echo "$1: identical ($(wc -l <"$dir/out") lines)"
  else
    echo "$1 differs:"; diff "$dir/serial" "$dir/out" | head -n 40; fail=1
  fi
}
