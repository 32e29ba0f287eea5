-- Collective calls made by some ranks only (issue 16; test lua_mpi_calls
-- through mpi_calls.sh): every rank runs the script and must make the same
-- calls; a save, an output, a cycle or os.tmpname under a branch on
-- seixo.rank() would leave the ranks that make it waiting for ever (a
-- save by rank 0 alone hung before the check). Each scene must stop every
-- rank at once, with one message naming the ranks' calls; serially (one
-- rank does everything) it runs to its end.
--   save     m:save on rank 0 alone, the others cycling
--   output   m:output on rank 0 alone
--   tmpname  os.tmpname on rank 0 alone
--   cycle    a cycle on the last rank alone, the others at the script's end
--   query    a ball's position read on rank 0 alone after a cycle, which
--            left each rank its own balls: the read fetches it from its rank
--   handler  a bond_break handler set on rank 0 alone, the model whole on
--            every rank (registering it then makes no collective call):
--            its cycles end at multiples of 100 steps, the others' do not
--            (it hung)
--   time     a time limit that differs on rank 0: its cycles stop at
--            another step (it hung)
--   models   one call on two models, rank 0 saving one and the others
--            another, after a cycle of each: the gathers of two models
--            would have paired (the check named the call, not its model)
--   receive  seixo.receive on rank 0 alone, the others cycling: no
--            message can come (it hung); serially no receive
--   receives seixo.receive on every rank, none sending (it hung)
--   caught   a callback failing on the last rank alone, its error caught
--            with pcall there and the script going on: the ranks' calls
--            part at the script's end, and the message names the caught
--            error (it named only the calls that differed)
--   path     m:save on every rank, each to a path of its own (a rank's
--            number or its clock in the name): rank 0 wrote its file
--            alone, and a later load failed on the others
--   load     seixo.load on rank 0 alone (every rank reads the file
--            itself, and none goes on before all have)
local scene = arg and arg[1] or "save"
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
local first = seixo.rank() == 0
local base = "calls_" .. scene -- in the folder mpi_calls.sh runs in (a run that fails leaves its files)
if scene == "save" then
  if first then m:save(base .. ".h5") end
  m:cycle(100)
elseif scene == "output" then
  if first then m:output{path = base .. "_series.h5"} end
  m:cycle(100)
elseif scene == "tmpname" then
  if first then os.remove(os.tmpname()) end
  m:cycle(100)
elseif scene == "cycle" then
  if seixo.rank() == seixo.ranks() - 1 then m:cycle(100) end
elseif scene == "handler" then
  local _ = m:contacts() -- every rank: the state whole again
  if first then m:on("bond_break", function() end) end
  m:cycle(300)
elseif scene == "time" then
  m:solve{time = first and 0.001 or 0.002}
elseif scene == "models" then
  local other = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
  m:cycle(10)
  other:cycle(10)
  ;(first and m or other):save(base .. ".h5")
  m:cycle(100)
elseif scene == "query" then
  m:cycle(10)
  local b = m:ball(1)
  if first then print(b.pos) end
  m:cycle(100)
elseif scene == "receive" then
  if first and seixo.ranks() > 1 then seixo.receive() end
  m:cycle(100)
elseif scene == "receives" then
  if seixo.ranks() > 1 then seixo.receive() end
elseif scene == "caught" then
  local at = m:step() + 50
  m:on("after", function()
    if m:step() == at and seixo.rank() == seixo.ranks() - 1 then error("boom") end
  end)
  pcall(m.cycle, m, 100)
  m:cycle(100)
elseif scene == "path" then
  m:save(base .. "_" .. seixo.rank() .. ".h5")
  m:cycle(100)
elseif scene == "load" then -- every rank reads the file: rank 0 alone cannot
  m:save(base .. ".h5")
  if seixo.rank() == 0 then seixo.load(base .. ".h5") end
  m:cycle(100)
else
  error("mpi_calls.lua: scene save, output, tmpname, cycle, query, handler, time, models, receive, receives, caught, "
        .. "path or load expected, got " .. tostring(scene))
end
print("ended " .. scene)
for _, suffix in ipairs{"", ".h5", "_series.h5", "_series.xmf", "_0.h5"} do os.remove(base .. suffix) end
