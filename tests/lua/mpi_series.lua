-- A triaxial series under mpirun (issue 16; test lua_mpi_series through
-- mpi_same.sh): the specimen's genesis runs decomposed over the ranks, and
-- lab.series hands its tests to the ranks, each test whole on one rank
-- (lab/series.lua, run_ranks), as lab.series{jobs} runs them in processes. Prints
-- every test's results to the bit, the fit, the quasi-static check, the
-- log lines the script's log function saw (sorted: the tests end in an
-- order of the ranks' pace), a file a test wrote over an older one, and a
-- series whose log function raises, which must all be the serial run's in
-- turn. Under mpirun it also fails unless the tests ran on the ranks
-- rank 0 hands them to first (the longest first: rank 1 the half-rate
-- test, ...), and unless every rank saw the same log lines, the same
-- errors, the same file and the same next random number as rank 0 (the
-- ranks above 0 print to /dev/null: they send theirs to rank 0). Then a
-- model made after the series is decomposed and cycles (its number in the
-- ranks' same-call checks is the same on every rank) and says "ranks N".
local lab = require "seixo.lab"
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local R = seixo.ranks()
local seen = {} -- what this rank saw, compared with rank 0's at the end
local function see(what) seen[#seen + 1] = tostring(what) end

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'") -- rank 0's, once (a shell command is rank 0's alone)
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.4e-3, 0.66e-3},
                          seed = 3, path = dir .. "/spec.h5", log = false}
-- an older file where the UCS writes its CSV: the ranks above 0 hold a
-- shadow of it, stale once a test has written the real one
-- (its CSV through io.open; its state and view from C: m:save, m:output)
local outs = {"/series_ucs.csv", "/series_ucs.h5", "/series_ucs_view.xmf"}
for _, name in ipairs(outs) do
  local old = assert(io.open(dir .. name, "w"))
  old:write("old\n")
  old:close()
end
local lines = {}
local s = lab.series(spec, {confining = {0, 2e6, 5e6}, quasi_static = true, out = dir .. "/series", plot = false,
                            jobs = R == 1 and 1 or nil, log = function(l) lines[#lines + 1] = l end})
if R > 1 then
  -- tests 1-3 (sigma3 0, 2, 5 MPa) and the half-rate test 4, handed out
  -- longest first: 4, 3, 2, 1 to ranks 1, 2, ..., then rank 0 its own
  local first = {4, 3, 2, 1}
  for r = 1, math.min(R, 4) - 1 do
    if s.ran_on[first[r]] ~= r then error(string.format("test %d ran on rank %s, not %d", first[r], s.ran_on[first[r]], r)) end
  end
  if s.ran_on[first[math.min(R, 4)]] ~= 0 then error("rank 0 did not run the test after the handed-out ones") end
  if s.jobs ~= math.min(R, 4) then error(string.format("the series took %d ranks, not %d", s.jobs, math.min(R, 4))) end
end
for _, r in ipairs(s.tests) do
  print(string.format("%s %g: peak %a E %a nu %a cracks %d/%d rows %d steps %d", r.kind, r.confining, r.peak, r.young,
                      r.poisson, r.cracks.tension, r.cracks.shear, #r.rows, r.steps))
end
print(string.format("fit c %a phi %a; half rate %a, %a apart", s.fit.c, s.fit.phi, s.quasi_static.test.peak,
                    s.quasi_static.change))
-- each test's own log line ends with its wall time: cut it off
for i, l in ipairs(lines) do lines[i] = l:gsub(", [%d.]+ s;", ";") end
table.sort(lines)
print(#lines .. " log lines")
for _, l in ipairs(lines) do
  print(l)
  see(l)
end
for _, name in ipairs(outs) do
  local head = assert(io.open(dir .. name, "rb")):read(5):gsub("[^%w<?]", ".")
  print(name .. " begins: " .. head)
  see(head)
end
-- the tests fail (every one: a negative strain limit), on whichever rank runs them
local ok, err = pcall(lab.series, spec, {confining = {0, 2e6}, max_strain = -1, log = false})
print("failed:", not ok, tostring(err):match("max_strain[^\n]*"))
see(err)
-- a log function that raises at a test's line (inside rank 0's own test,
-- or as a rank's result comes in): every rank raises it, none waits
local said = {}
ok, err = pcall(lab.series, spec, {confining = {0, 2e6}, log = function(l)
  said[#said + 1] = l
  if l:find("lab.triaxial: sigma3 2 MPa", 1, true) then error("the log refuses " .. l:match("sigma3 %d MPa")) end
end})
print("log raised:", not ok, tostring(err):match("the log refuses.*"))
see(err)
see(#said)
see(math.random(1, 1 << 30)) -- the ranks draw alike after a series
see(seixo.decompose())
local m = dofile(here .. "mpi_bed.lua")(10) -- decomposed again, its calls numbered alike
see(m:ranks())
print("a model after it:", m:step(), m:hash())
-- every rank's view against rank 0's
local digest = table.concat(seen, "\n")
if R > 1 then -- a rank out of range is named with the range
  local ok, e = pcall(seixo.send, R, "x")
  assert(not ok and e:match("another rank expected %(0 to " .. R - 1 .. ", not this one, %d+%), got " .. R), e)
end
if seixo.rank() > 0 then
  seixo.send(0, digest)
else
  for _ = 1, R - 1 do
    local text, from = seixo.receive(true)
    if text ~= digest then
      error(string.format("rank %d saw otherwise than rank 0:\n%s\n-- rank 0:\n%s", from, text, digest))
    end
  end
end
os.execute("rm -rf '" .. dir .. "'")
