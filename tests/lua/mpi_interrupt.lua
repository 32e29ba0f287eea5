-- Interrupts under mpirun (issue 16), for mpi_same.sh: every rank count
-- must print what the serial run prints. A SIGUSR1 (what mpirun forwards
-- to every rank, and SLURM's --signal sends before the wall time) sent by
-- a script to its own process:
--   (none)  to the last rank alone: every rank's cycle stops at the same
--           step, as an `interrupted at step N` error each catches
--           (pcall); the script saves and goes on, and ends where an
--           uninterrupted serial run ends, to the bit (serially the signal
--           stops the only rank, in its callback)
--   late    the same, and rank 0 gets its copy of the signal 60 steps
--           after the stop (mpirun's forwarding of one signal reaches the
--           ranks at their own times): not a second interrupt; two
--           signals at once to the last rank are one stop
--   alone   seixo.decompose(false): each rank cycles a model of its own
--           and stops it on its own signal (counted by seixo.interrupts()),
--           and the next decomposed cycle runs to its end (those requests
--           were answered: it stopped at once)
local scene = arg and arg[1] or ""
local last = seixo.ranks() - 1
local function pour()
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("sand", {density = 2600, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})
  m:wall{kind = "box", min = {0, 0}, max = {0.4, 0.6}}
  m:generate{count = 600, radius = {4e-3, 6e-3}, region = {box = {{0, 0.1}, {0.4, 0.6}}}, seed = 3}
  return m
end
local function signal() os.execute("kill -USR1 $PPID") end
local before = seixo.interrupts()
if scene == "alone" then
  seixo.decompose(false)
  local own = pour()
  own:on("after", function() if own:step() == 300 then signal() end end)
  local ok, err = pcall(own.cycle, own, 100000)
  assert(not ok and tostring(err):match("interrupted at step 300"), "the rank's own cycle: " .. tostring(err))
  print("own model interrupted, interrupts counted: " .. seixo.interrupts() - before)
  seixo.decompose(true)
  local m = pour()
  m:cycle(400)
  print(string.format("then a decomposed cycle to step %d, hash %s", m:step(), m:hash()))
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  return
end
local m = pour()
local signal_at, total = 700, 3000
m:on("after", function()
  if m:step() == signal_at and seixo.rank() == last then
    signal()
    if scene == "late" and seixo.ranks() > 1 then signal() end
  end
  if scene == "late" and m:step() == signal_at + 76 and seixo.rank() == 0 and last > 0 then signal() end
end)
local ok, err = pcall(m.cycle, m, total)
assert(not ok and tostring(err):match("interrupted at step %d+"), "the cycle must stop: " .. tostring(err))
local at = m:step()
if seixo.ranks() > 1 then -- where the ranks agree: a step they all check, within 16 of the signal
  assert(at % 16 == 0 and at > signal_at and at <= signal_at + 16,
         string.format("stopped at step %d, signal at %d", at, signal_at))
end
print("caught: interrupted at step N") -- serially "(in a callback)" follows: the signal came in one
print("interrupts counted: " .. seixo.interrupts() - before)
local path = os.tmpname()
m:save(path) -- a collective call: every rank is here, in step
assert(seixo.load(path):hash() == m:hash(), "the saved model is the interrupted one")
os.remove(path)
m:cycle(total - at) -- the rest, uninterrupted (late: rank 0's copy comes in it)
print(string.format("step %d hash %s", m:step(), m:hash()))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
