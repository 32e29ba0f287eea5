-- Files under mpirun (issue 16; test lua_mpi_files through mpi_same.sh):
-- every rank runs the script, but while the ranks share models rank 0
-- alone writes the real files and the other ranks read back the shadows
-- of what they wrote (src/lua/rank_files.c); with seixo.decompose(false)
-- each rank writes its own (a part each, all there after the first
-- cycle). A log opened before the model has its lines once, not once per
-- rank, as has one appended after each cycle (its header written while it
-- is empty); a file rewritten, updated in place, written through io.output,
-- renamed, removed (rank 0 running late: the others must not find its
-- files still there), refused in a folder that is not there or without a
-- name, a clump template's spheres read back by C, a file removed then
-- written by m:save for every rank, a file saved then renamed, and
-- os.tmpname's file removed (rank 0 first), files rewritten or made and
-- removed while the ranks worked alone, a history's CSV appended to, give every rank rank 0's answers
-- (and errors of Lua's io functions name the script's line):
-- each answer goes into the model (a ball's size), so that a rank which
-- read something else stops the next cycle ("the model differs between
-- the ranks"), and rank 0 prints them, which must be the serial run's.
local base = os.tmpname() -- rank 0's name, on every rank
-- a log opened before the model, written after it: its lines once
local early = assert(io.open(base .. ".early", "a"))
-- with seixo.decompose(false) each rank writes its own files, as a script
-- splitting work by seixo.rank() does
seixo.decompose(false)
local part = io.open(string.format("%s.part%d", base, seixo.rank()), "w")
part:write("part\n")
part:close()
seixo.decompose(true)
local m = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "mpi_bed.lua")(100)
-- rank 0 late: the others read this log back from their shadows, not
-- from the disk before rank 0 has written it (seixo.decompose switched
-- off and on meanwhile)
if seixo.rank() == 0 then os.execute("sleep 0.3") end
early:write("after the first cycle\n")
early:close()
local record = {}
local function note(...)
  local t = table.pack(...)
  for i = 1, t.n do
    local s, at = tostring(t[i]), 1
    local a, b = s:find(base, 1, true) -- the path differs from the serial run's
    if a then s = s:sub(1, a - 1) .. "BASE" .. s:sub(b + 1) end
    t[i] = io.type(t[i]) and "a file" or s
  end
  record[#record + 1] = table.concat(t, " ", 1, t.n)
end

local parts = true -- every rank's, after the cycle every rank has joined
for r = 0, seixo.ranks() - 1 do parts = parts and io.open(string.format("%s.part%d", base, r)) ~= nil end
note("every rank's part", parts)
for line in io.lines(base .. ".early") do note("early", line) end

local log = base .. ".log"
for _ = 1, 3 do
  m:cycle(50)
  local f = assert(io.open(log, "a"))
  if f:seek("end") == 0 then f:write("step,balls\n") end
  f:write(string.format("%d,%d\n", m:step(), m:ball_count()))
  f:close()
end
for line in io.lines(log) do note("log", line) end

local f = assert(io.open(base .. ".txt", "w"))
f:write("first\n")
f:close()
f = assert(io.open(base .. ".txt", "w"))
f:write("second\n")
f:close()
note("rewritten", io.open(base .. ".txt"):read("a"))
f = assert(io.open(base .. ".txt", "r+"))
f:write("S")
f:seek("set", 0)
note("updated", f:read("a"))
f:close()

io.output(base .. ".out")
io.write("through io.output\n")
io.close()
io.output(io.stdout)
io.input(base .. ".out")
note("io.input", io.read("l"))
io.close()
io.input(io.stdin)

-- rank 0 late, so the others remove and rename first: they must not find
-- rank 0's files still there (os.execute is no collective call)
if seixo.rank() == 0 then os.execute("sleep 0.5") end
note("rename", os.rename(base .. ".txt", base .. ".moved"))
note("moved", io.open(base .. ".moved"):read("a"))
note("old name", io.open(base .. ".txt"))
note("remove", os.remove(base .. ".moved"))
note("removed", io.open(base .. ".moved"))
note("remove again", os.remove(base .. ".moved"))
note("lines of a removed file", pcall(io.lines, base .. ".moved"))
note("no folder", io.open(base .. ".none/file", "w"))
note("no name", io.open("", "w"))

-- a file the script removed, then saved by m:save (rank 0 writes it for
-- all): every rank reads the saved file
f = assert(io.open(base .. ".h5", "w"))
f:write("not a model")
f:close()
os.remove(base .. ".h5")
m:save(base .. ".h5")
f = io.open(base .. ".h5", "rb")
note("saved after a remove", f ~= nil, f and f:read(4) == "\137HDF")
if f then f:close() end
-- saved (a collective call), then renamed and removed by rank 0 first:
-- the others must not find it missing, and must find the name it took
m:save(base .. ".tmp.h5")
if seixo.rank() > 0 then os.execute("sleep 0.3") end
note("saved, renamed", os.rename(base .. ".tmp.h5", base .. ".h5"))
f = io.open(base .. ".h5", "rb")
note("the new name", f ~= nil, f and f:read(4) == "\137HDF")
if f then f:close() end
note("the old name", io.open(base .. ".tmp.h5", "rb"))
local t = os.tmpname()
if seixo.rank() > 0 then os.execute("sleep 0.3") end
note("os.tmpname's file removed", os.remove(t))

f = assert(io.open(base .. ".spheres", "w"))
f:write("0 0 1e-3\n1.5e-3 0 8e-4\n")
f:close()
local t = m:clump_template("pair", base .. ".spheres")
note("template", #t.pebbles, string.format("%.6g %.6g", t.volume, t.centroid[1]))

-- a file the last rank rewrites, and one it makes and removes, while the
-- ranks work alone: once they share again every rank finds what is on the
-- disk (the others' shadow of the first was stale; the second is gone)
f = assert(io.open(base .. ".alone", "w"))
f:write("before\n")
f:close()
seixo.decompose(false)
if seixo.rank() == seixo.ranks() - 1 then
  f = assert(io.open(base .. ".alone", "w"))
  f:write("the last rank's\n")
  f:close()
  assert(io.open(base .. ".gone", "w")):close()
  assert(os.remove(base .. ".gone"))
end
seixo.decompose(true)
note("rewritten while alone", assert(io.open(base .. ".alone")):read("a"))
note("made and removed while alone", io.open(base .. ".gone"))
note("removed again", os.remove(base .. ".gone"))
-- an error of Lua's own io function names the script's line, on rank 0
-- too (its io functions are wrapped there)
note("an io.lines error", select(2, pcall(function() for _ in io.lines(base .. ".none") do end end)))
note("an io.open error", select(2, pcall(function() return io.open(base, "q") end)))

-- a Lua file the script writes, rank 0 late, then run by dofile and
-- loadfile (an MPI user's finding: the others read the disk before rank 0
-- had written it, and found nothing)
if seixo.rank() == 0 then os.execute("sleep 0.3") end
f = assert(io.open(base .. ".params.lua", "w"))
-- (a UTF-8 mark and a # line first, both of which Lua skips)
f:write("\xEF\xBB\xBF#!/usr/bin/env seixo\nreturn {k = 7, name = 'params', src = debug.getinfo(1, 'S').short_src}\n")
f:close()
-- (the chunk is named by the file's own path on every rank, not by a shadow's)
note("dofile", dofile(base .. ".params.lua").k, loadfile(base .. ".params.lua")().name,
     dofile(base .. ".params.lua").src)
os.remove(base .. ".params.lua")

-- a history's CSV the model writes for every rank (rank 0 writes it), then
-- appended to by the script, rank 0 first and the others late (they must
-- start from the file rank 0 wrote, not from an empty shadow, nor from
-- the file with rank 0's lines already appended: a review's finding, the
-- others read 1 line of 5)
m:history("hist_step", "step")
m:cycle(3)
local csv = base .. ".hist.csv"
m:history_csv(csv, {"hist_step"})
if seixo.rank() > 0 then os.execute("sleep 0.3") end
local fa = assert(io.open(csv, "a"))
fa:write("appended\n")
fa:close()
local lines = {}
for line in io.lines(csv) do lines[#lines + 1] = line end
note("a history's CSV appended to", #lines, lines[#lines])
os.remove(csv)

-- a shell command rank 0 runs alone, late, then seixo.barrier(): its file
-- is there for every rank (an MPI user's finding: no call could wait for it)
if seixo.rank() == 0 then os.execute("sleep 0.3; echo from-the-shell > " .. base .. ".shell") end
seixo.barrier()
note("after the barrier", io.open(base .. ".shell"):read("l"))
seixo.barrier() -- (every rank has read it before rank 0 removes it)
if seixo.rank() == 0 then os.remove(base .. ".shell") end

local sum = 0
for _, line in ipairs(record) do
  print(line)
  for i = 1, #line do sum = (sum * 31 + line:byte(i)) % 1000003 end
end
m:ball{pos = {0.02, 0.045}, radius = 1e-3 * (1 + sum / 1e7)}
m:cycle(100)
print("end", m:step(), m:hash())
-- after a cycle: every rank has read them (rank 0 removing one while a
-- rank still reads it from the disk is the race of files the other ranks
-- do not shadow)
for _, suffix in ipairs{"", ".log", ".out", ".spheres", ".h5", ".early", ".alone"} do os.remove(base .. suffix) end
seixo.decompose(false) -- each rank removes its own
os.remove(string.format("%s.part%d", base, seixo.rank()))
