-- Standard output under mpirun (issue 16; test lua_mpi_stdout through
-- mpi_same.sh): every rank runs the script, and what it writes to standard
-- output must come once, from rank 0, whichever way it is written: print,
-- io.write, io.stdout:write, a shell command's output; so the output is the
-- serial run's for every rank count.
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(200)
print("print", m:step(), m:hash())
io.write(string.format("io.write %d %s\n", m:step(), m:hash()))
io.stdout:write("io.stdout:write ", m:ball_count(), "\n")
io.stdout:flush()
os.execute("echo a shell command")
m:cycle(200)
io.write("after a second cycle ", m:hash(), "\n")
