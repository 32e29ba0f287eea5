-- lab.calibrate under mpirun -np 2: every rank runs this script; rank 0
-- searches and runs its share of the runs, rank 1 runs the others, and both
-- return the same result. Two calibrations in a row: each is collective.
--   mpirun --allow-run-as-root --oversubscribe -np 2 build/seixo tests/lua/calibrate_mpi.lua
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local lab = require("seixo.lab")

local rank = seixo.rank()
local calls = 0
local function synthetic(material, seed)
  calls = calls + 1
  local kr = material.stiffness_ratio
  return {E = 1.1 * material.modulus * (1 + 0.1 / kr) * (1 + 0.02 * (seed - 2)), nu = 0.5 - 0.6 / (kr + 1),
          UCS = 1.3 * material.bond.tensile_strength * (1 + 0.04 * (seed - 2))}
end

test("two ranks", function() eq(seixo.ranks(), 2, "started by mpirun -np 2") end)

local results = {}
for i, strength in ipairs({120e6, 90e6}) do
  test("calibration " .. i .. ": the known parameters on both ranks, runs on both ranks", function()
    calls = 0
    local log = string.format("calibrate_mpi%d.csv", i)
    if rank == 0 then os.remove(log) end
    local r = lab.calibrate{targets = {E = 1.1 * 50e9 * 1.05, nu = 0.3, UCS = 1.3 * strength},
                            parameters = {modulus = {10e9, 200e9}, stiffness_ratio = {1, 6}, strength = {30e6, 600e6}},
                            evaluate = synthetic, seeds = 3, tolerance = 1e-2, maxeval = 30, log = log,
                            out = string.format("calibrate_mpi%d", i), plot = false, print = rank == 0 and print or false}
    near(r.parameters.modulus, 50e9, 2e-2)
    near(r.parameters.stiffness_ratio, 2, 2e-2)
    near(r.parameters.strength, strength, 2e-2)
    check(calls > 0, string.format("rank %d ran no run", rank))
    if rank == 0 then
      local csv = require("seixo.util").read_csv(log)
      check(csv.rows > calls, "the other rank ran some of the logged runs")
    end
    results[i] = string.format("%.10g %.10g %.10g", r.parameters.modulus, r.parameters.stiffness_ratio, r.parameters.strength)
  end)
end
test("an error of the search on rank 0 is raised on every rank, none waiting for ever", function()
  -- a log of another calibration's columns: rank 0 finds it as it starts
  -- searching (the other ranks are waiting for jobs by then)
  local log = "calibrate_mpi_other.csv"
  local f = assert(io.open(log, "w")) -- rank 0's file (the others write a shadow)
  f:write("candidate,seed,other\n1,1,2\n")
  f:close()
  raises(function()
    lab.calibrate{targets = {E = 50e9}, parameters = {modulus = {10e9, 200e9}}, evaluate = synthetic, seeds = 1,
                  maxeval = 4, log = log, plot = false, print = false}
  end, "has the columns")
  os.remove(log)
end)

test("the models after a calibration are decomposed again", function()
  eq(seixo.decompose(), true)
  local m = seixo.model{dim = 2}
  eq(m:ranks(), 2)
  m:close()
end)
print(string.format("rank %d: %s | %s", rank, results[1] or "-", results[2] or "-"))
T.done()
