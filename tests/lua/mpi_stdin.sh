#!/bin/sh
# Standard input under mpirun, which gives it to rank 0 alone: a script
# read from it (`seixo - ARGS`) and an interactive session fed to
# `seixo -i` run alike on every rank (rank 0 reads, the others take its
# input) and print what the serial run prints, serially and with 1 to 4
# ranks (the session's errors reported once; its banner and prompts,
# which a serial run reading a pipe does not show), each run within a time
# limit (a rank waiting for input it never gets would hang), and a line
# failing on one rank alone ends the session with its message; and a bad
# option is refused with its message once; --profile prints a table per
# rank, named by its rank. Skipped (77) without mpirun.
#   mpi_stdin.sh SEIXO SCRIPT 'ARGS'
# SCRIPT prints "ranks N" on stderr once its model is made (mpi_pour.lua).
set -u
seixo=$1
script=$2
args=$3
. "$(dirname "$0")/mpi_env.sh" # mpirun or skip; root, ranks, dir, same_as_serial
# the session: a statement over three lines, an expression's value, a line
# that does not compile, then the script with its arguments
{
  printf 'total = 0\nfor i = 1, 3 do\n  total = total + i\nend\nprint("total", total)\n6 * 7\n1 +* 2\n'
  printf 'arg = {%s}\n' "$(echo "$args" | sed 's/ /, /g')"
  printf 'dofile("%s")\nprint("after", total)\n' "$script"
} >"$dir/session"
fail=0
for mode in script session; do
  if [ $mode = script ]; then input=$script; set -- -; else input=$dir/session; set -- -i; fi
  # shellcheck disable=SC2086 # the arguments are several words
  if ! timeout 300 "$seixo" "$@" $([ $mode = script ] && echo "$args") <"$input" >"$dir/serial" 2>"$dir/err"; then
    echo "serial $mode failed:"; cat "$dir/err"; exit 1
  fi
  echo "$mode, serial:"; cat "$dir/serial"
  for np in $ranks; do
    # shellcheck disable=SC2086
    timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" "$@" $([ $mode = script ] && echo "$args") \
      <"$input" >"$dir/out" 2>"$dir/err"
    status=$?
    if [ $status -ne 0 ]; then
      echo "$mode, -np $np: exit status $status ($([ $status -eq 124 ] && echo 'a hang: stopped after 300 s'))"
      cat "$dir/err"; fail=1; continue
    fi
    # the session under mpirun, whose ranks have no terminal, shows its
    # banner and prompts (on stdout: mpirun forwards stderr apart, out of
    # order with it); the rest is what the serial run prints
    if [ $mode = session ]; then
      if ! head -n 1 "$dir/out" | grep -q "^seixo .* on $np ranks\{0,1\}; help() for help, Ctrl-D quits" ||
         ! grep -q "^> \(> \)*>> >> " "$dir/out"; then
        echo "$mode, -np $np: no banner, or no prompts (> and >> for the lines of a statement):"
        head -n 3 "$dir/out"; fail=1
      fi
      sed -e 1d -e 's/^\(>>* \)*//' "$dir/out" | sed -e '${/^$/d;}' >"$dir/bare" && mv "$dir/bare" "$dir/out"
    fi
    same_as_serial "$mode, -np $np" "$np"
    # the session's error, met by every rank, reported once (by rank 0)
    if [ $mode = session ] && [ "$(grep -c "unexpected symbol" "$dir/err")" != 1 ]; then
      echo "$mode, -np $np: the syntax error is not reported once:"; cat "$dir/err"; fail=1
    fi
  done
done
# a session line that fails on the last rank only, then ends (1), or goes
# on to a collective call the others make (2); a line making a collective
# call on rank 0 only (3): the ranks differ after it, so the job ends with
# one message, said once (by rank 0), and the next line runs nowhere
bed="m = dofile('$(dirname "$0")/mpi_bed.lua')(10)"
for np in $ranks; do
  [ "$np" -lt 2 ] && continue
  for case in 1 2 3; do
    case $case in
      1) line='if seixo.rank() == seixo.ranks() - 1 then error("on the last rank") end'
         said="^seixo: rank $((np - 1)) of $np: stdin:1: on the last rank (on some ranks only" ;;
      2) line='if seixo.rank() == seixo.ranks() - 1 then error("on the last rank") end m:cycle(2)'
         said="^seixo: rank $((np - 1)) of $np: stdin:1: on the last rank (on some ranks only" ;;
      3) line='if seixo.rank() == 0 then m:cycle(3) end'
         said="the ranks made different calls: rank 0 is in .*m:cycle" ;;
    esac
    printf '%s\n%s\nprint("went on")\n' "$bed" "$line" |
      timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" -i >"$dir/out" 2>"$dir/err"
    rc=$?
    if [ $rc = 0 ] || [ $rc = 124 ] || grep -q "went on" "$dir/out" || [ "$(grep -c "$said" "$dir/err")" != 1 ] ||
       grep -q "MPI_ERR" "$dir/err"; then
      echo "line $case failing on some ranks, -np $np: exit status $rc, the message not once:"
      cat "$dir/out" "$dir/err"; fail=1
    else
      echo "line $case failing on some ranks, -np $np: the session ended with its message"
    fi
  done
done
# a script file that reads standard input (an MPI user's finding: io.read
# gave nil on the ranks above 0): io.read's formats and io.lines() with
# and without formats, each value put into the model, so a
# rank that read something else stops the next cycle; it prints what the
# serial run prints
cat >"$dir/reads.lua" <<EOF
local m = dofile('$(dirname "$0")/mpi_bed.lua')(40)
local word, n, x = io.read("l", "n", "n")
local count = 0
for line in io.lines() do
  count = count + 1
  if line == "--" then break end
end
local tail = io.read("l")
local more = {}
for a, b in io.lines(nil, "n", "n") do more[#more + 1] = a + b end
local sum = n + x + count + #tail + #more + more[1]
m:ball{pos = {0.02, 0.045}, radius = 1e-3 * (1 + sum / 1e4)}
m:cycle(10)
print(word, n, x, count, tail, #more, more[1], more[2], io.read("l"), m:hash())
EOF
printf 'hello\n42 2.5\na\nb\n--\nthe tail\n1 2\n3 4\n' >"$dir/input"
timeout 300 "$seixo" "$dir/reads.lua" <"$dir/input" >"$dir/serial" 2>"$dir/err" || { echo "reads, serial:"; cat "$dir/err"; exit 1; }
echo "reads, serial:"; cat "$dir/serial"
for np in $ranks; do
  timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" "$dir/reads.lua" <"$dir/input" >"$dir/out" 2>"$dir/err"
  rc=$?
  if [ $rc != 0 ]; then echo "reads, -np $np: exit status $rc"; cat "$dir/err"; fail=1; continue; fi
  same_as_serial "reads, -np $np" "$np"
done
# a bad option, which every rank parses alike: refused, said once (rank 0)
for np in $ranks; do
  timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" --frob >"$dir/out" 2>"$dir/err"
  rc=$?
  if [ $rc = 0 ] || [ $rc = 124 ] || [ "$(grep -c "unrecognized option '--frob'" "$dir/err")" != 1 ]; then
    echo "--frob, -np $np: exit status $rc, the message not once:"; cat "$dir/err"; fail=1
  else
    echo "--frob, -np $np: refused, said once"
  fi
done
# --profile: a table per rank, each rank's own times, each named by its rank
for np in $ranks; do
  [ "$np" -lt 2 ] && continue
  timeout 300 mpirun $root --oversubscribe -np "$np" "$seixo" --profile \
    -e "local m = dofile('$(dirname "$0")/mpi_bed.lua')(50)" >"$dir/out" 2>"$dir/err"
  r=0
  while [ $r -lt "$np" ]; do
    if [ "$(grep -c "^seixo: profile (rank $r of $np) of a 2D model of 100 balls at step 50:" "$dir/err")" != 1 ]; then
      echo "--profile, -np $np: rank $r's table not named once:"; cat "$dir/err"; fail=1
    fi
    r=$((r + 1))
  done
done
exit $fail
