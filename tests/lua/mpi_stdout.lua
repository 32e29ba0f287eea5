-- Standard output under mpirun (issue 16; test lua_mpi_stdout through
-- mpi_same.sh): every rank runs the script, and what it writes to standard
-- output must come once, from rank 0, whichever way it is written: print,
-- io.write, io.stdout:write, a shell command's output; so the output is the
-- serial run's for every rank count.
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
m:generate{count = 100, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.03}}}, seed = 2}
m:wall{kind = "box", min = {0, 0}, max = {0.04, 0.05}}
m:cycle(200)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print("print", m:step(), m:hash())
io.write(string.format("io.write %d %s\n", m:step(), m:hash()))
io.stdout:write("io.stdout:write ", m:ball_count(), "\n")
io.stdout:flush()
os.execute("echo a shell command")
m:cycle(200)
io.write("after a second cycle ", m:hash(), "\n")
