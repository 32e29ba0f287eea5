-- Standard output under mpirun (issue 16; test lua_mpi_stdout through
-- mpi_same.sh): every rank runs the script, and what it writes to standard
-- output must come once, from rank 0, whichever way it is written: print,
-- io.write, io.stdout:write, a shell command's output; so the output is the
-- serial run's for every rank count. seixo's own warnings about a shared
-- model (a unit, a mesh's repair), on standard error, come once too
-- (mpi_same.sh fails on a warning printed twice).
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(200)
print("print", m:step(), m:hash())
io.write(string.format("io.write %d %s\n", m:step(), m:hash()))
io.stdout:write("io.stdout:write ", m:ball_count(), "\n")
io.stdout:flush()
os.execute("echo a shell command")
m:cycle(200)
io.write("after a second cycle ", m:hash(), "\n")
-- warnings about the shared model: once, from rank 0
m:material("light", {density = 2.5})
local q = seixo.model{dim = 3}
q:material("a")
q:wall{kind = "mesh", vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 0}}, triangles = {{1, 2, 3}, {1, 1, 4}},
       repair = true}
