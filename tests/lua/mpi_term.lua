-- A SIGTERM that ends a job under mpirun (mpirun's own, a scheduler's:
-- test lua_mpi_term through mpi_term.sh) leaves no rank's folder of
-- private copies of the script's files behind in $TMPDIR: the last rank
-- writes a file (its copy made there), then is sent a SIGTERM.
local f = assert(io.open("term_log.txt", "w"))
f:write("a line\n")
f:close()
if seixo.rank() == seixo.ranks() - 1 then
  local made = io.popen("ls '" .. os.getenv("TMPDIR") .. "' | grep -c seixo-rank"):read("l")
  io.stderr:write("copies' folders before the signal: " .. made .. "\n")
  os.execute("kill -TERM $PPID")
  for _ = 1, 100 do os.execute("sleep 0.1") end -- ended before this loop ends
end
seixo.barrier()
print("not ended")
