-- A triaxial series under mpirun (issue 16; test lua_mpi_series through
-- mpi_same.sh): the specimen's genesis runs decomposed over the ranks, and
-- lab.series hands its tests to the ranks, each test whole on one rank
-- (lab.lua, run_ranks), as lab.series{jobs} runs them in processes. Prints
-- every test's results to the bit, the fit, the quasi-static check and the
-- log lines the script's log function saw (sorted: the tests end in an
-- order of the ranks' pace), which must be the serial run's in turn; says
-- on stderr over how many ranks the genesis ran ("ranks N") and fails
-- unless the series' tests ran on min(ranks, tests) of them. Then a series whose
-- tests fail raises their error on every rank alike, and the models made
-- after it are decomposed again.
local lab = require "seixo.lab"
local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'") -- rank 0's, once (a shell command is rank 0's alone)
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.4e-3, 0.66e-3},
                          seed = 3, path = dir .. "/spec.h5", log = false}
local lines = {}
local s = lab.series(spec, {confining = {0, 2e6, 5e6}, quasi_static = true, out = dir .. "/series", plot = false,
                            jobs = seixo.ranks() == 1 and 1 or nil, log = function(l) lines[#lines + 1] = l end})
local want = seixo.ranks() > 1 and math.min(seixo.ranks(), 4) or 1
local took = {}
for _, r in ipairs(s.ran_on or {}) do took[r] = true end
local n = 0
for _ in pairs(took) do n = n + 1 end
if seixo.ranks() > 1 and (s.jobs ~= want or n ~= want or #s.ran_on ~= 4) then
  error(string.format("the series' 4 tests ran on %d ranks (jobs %d), not %d", n, s.jobs, want))
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
for _, l in ipairs(lines) do print(l) end
-- the tests fail (every one: a negative strain limit), on whichever rank runs them
local ok, err = pcall(lab.series, spec, {confining = {0, 2e6}, max_strain = -1, log = false})
print("failed:", not ok, tostring(err):match("max_strain[^\n]*"))
local m = seixo.model{dim = 2}
io.stderr:write(string.format("ranks %d\n", m:ranks()))
print("decomposed after it:", seixo.decompose())
os.execute("rm -rf '" .. dir .. "'")
