-- Errors in a script run under mpirun (issue 16; tests lua_mpi_fail_*
-- through mpi_stops.sh): every rank runs the script, so an error in it is
-- met by every rank alike, and the message must come once, not once per
-- rank; an error met by one rank alone must stop all of them with its
-- message. Serially (one rank, the last) each scene fails the same way.
--   script     an error in the script, after a decomposed cycle
--   callback   an error in a callback, inside a decomposed cycle
--   last       an error on the last rank only, the others going on to
--              cycle (they wait for it: the error must end them)
local scene = arg and arg[1] or "script"
local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
m:generate{count = 100, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.04, 0.03}}}, seed = 2}
m:wall{kind = "box", min = {0, 0}, max = {0.04, 0.05}}
m:cycle(100)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print("cycled", m:step(), m:hash())
if scene == "script" then
  error("mpi_fail.lua: an error in the script, met by every rank")
elseif scene == "callback" then
  m:on("after", function(mm)
    if mm:step() == 150 then error("mpi_fail.lua: an error in a callback, met by every rank") end
  end, {every = 10})
  m:cycle(100)
elseif scene == "last" then
  if seixo.rank() == seixo.ranks() - 1 then error("mpi_fail.lua: an error on the last rank alone") end
  m:cycle(100)
else
  error("mpi_fail.lua: scene script, callback or last expected, got " .. tostring(scene))
end
print("not stopped")
