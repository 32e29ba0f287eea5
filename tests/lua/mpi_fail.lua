-- Errors in a script run under mpirun (issue 16; tests lua_mpi_fail_*
-- through mpi_stops.sh): every rank runs the script, so an error in it is
-- met by every rank alike, and the message must come once, not once per
-- rank; an error met by one rank alone must stop all of them with its
-- message. Serially (one rank, the last) each scene fails the same way.
--   script     an error in the script, after a decomposed cycle
--   callback   an error in a callback, inside a decomposed cycle
--   last       an error on the last rank only, the others going on to
--              cycle (they wait for it: the error must end them; rank 0,
--              waiting in m:cycle's same-call check, reports it at once)
--   first      the same on rank 0 only (which reports at once: it no
--              longer waits 5 s to see whether the others fail alike)
--   busy       an error on rank 1 alone (serially rank 0) while the
--              last of 3 or more ranks computes for 7 s: rank 0 reports it,
--              once (the failing rank, whose own wait ended first, said it
--              again)
--   placed     a ball placed over another: the first step fails on the
--              rank that owns them, which names the placement, as
--              serially, not the timestep
--   overlap    two balls placed overlapping by 70 % of a radius, in the
--              bed's upper part (the last rank's): the first step passes,
--              and its check of the contacts (each rank its own, without
--              a gather) names the two balls on every rank
local scene = arg and arg[1] or "script"
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
-- a file written: the ranks above 0 hold a shadow of it when they fail
-- or are ended (mpi_stops.sh wants no shadow folder left in TMPDIR)
local note = assert(io.open((os.getenv("TMPDIR") or "/tmp") .. "/mpi_fail_note.txt", "w"))
note:write("cycled\n")
note:close()
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
elseif scene == "first" then
  if seixo.rank() == 0 then error("mpi_fail.lua: an error on rank 0 alone") end
  m:cycle(100)
elseif scene == "busy" then
  local R = seixo.ranks()
  if seixo.rank() == math.min(1, R - 1) then error("mpi_fail.lua: an error on rank 1 alone") end
  if R >= 3 and seixo.rank() == R - 1 then
    local t0 = seixo.clock()
    while seixo.clock() - t0 < 7 do end
  end
  m:cycle(100)
elseif scene == "placed" then
  m:ball{pos = m:ball(5).pos, radius = 1e-3}
  m:cycle(10)
elseif scene == "overlap" then
  m:ball{pos = {0.010, 0.045}, radius = 1e-3}
  m:ball{pos = {0.0113, 0.045}, radius = 1e-3}
  m:cycle(10)
else
  error("mpi_fail.lua: scene script, callback, last, first, busy, placed or overlap expected, got " .. tostring(scene))
end
print("not stopped")
