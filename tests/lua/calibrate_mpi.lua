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

-- rank 1's draw against rank 0's: the ranks must draw alike after a calibration
local function same_draw()
  local draw = tostring(math.random(1, 1 << 30))
  if rank == 1 then seixo.send(0, draw) return end
  eq(seixo.receive(true), draw, "rank 1's next random number against rank 0's")
end

test("after a calibration with its plot (rank 0's alone) the ranks draw alike", function()
  lab.calibrate{targets = {E = 50e9}, parameters = {modulus = {10e9, 200e9}}, evaluate = synthetic, seeds = 2,
                maxeval = 4, log = "calibrate_mpi_plot.csv", out = "calibrate_mpi_plot", print = false}
  same_draw()
  os.remove("calibrate_mpi_plot.csv")
  os.remove("calibrate_mpi_plot_convergence.png")
end)

-- a 2D specimen for runs that take a while (rank 0's own run polls for results)
local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.4e-3, 0.66e-3},
                          seed = 3, path = dir .. "/spec.h5", log = false}

test("a print that raises as rank 0 takes a record during its own run stops every rank, none waiting", function()
  -- rank 1's run fails at once; rank 0 is inside its own test when the
  -- record comes, and says "run failed" through the script's print
  local raised = false
  raises(function()
    lab.calibrate{targets = {E = 50e9}, parameters = {modulus = {10e9, 200e9}}, seeds = 2, maxeval = 2,
                  log = dir .. "/raise.csv", plot = false,
                  evaluate = function(mat)
                    if seixo.rank() == 1 then error("rank 1's run fails") end
                    lab.ucs(spec, {log = false, plot = false, max_steps = 3000})
                    return {E = mat.modulus}
                  end,
                  print = function(text)
                    if seixo.rank() == 0 and not raised and text:find("run failed", 1, true) then
                      raised = true
                      error("the print refuses")
                    end
                  end}
  end, "the print refuses")
end)

test("a search failing while a rank's large record is out stops every rank, and leaves no message behind", function()
  raises(function()
    lab.calibrate{targets = {E = 50e9}, parameters = {modulus = {10e9, 200e9}}, seeds = 2, maxeval = 2,
                  log = dir .. "/large.csv", plot = false,
                  evaluate = function()
                    if seixo.rank() == 0 then error("rank 0's run fails") end
                    local t = seixo.clock()
                    while seixo.clock() - t < 0.5 do end
                    error(string.rep("x", 200000)) -- a record far above MPI's eager sends
                  end,
                  print = function(text) if text:find("run failed", 1, true) then error("the print refuses") end end}
  end, "the print refuses")
  -- the ranks go on together: a series over them takes only its own results
  local s = lab.series(spec, {confining = {0, 2e6}, log = false, max_steps = 2000})
  eq(#s.tests, 2)
end)
os.execute("rm -rf '" .. dir .. "'")

test("a folder rank 0 alone made, while the other rank is already in lab.calibrate", function()
  -- (the output folders are checked before the runs, by rank 0, which
  -- writes them: checked on every rank, rank 1 found the folder missing)
  local out = os.tmpname()
  os.remove(out)
  if rank == 0 then
    local t = seixo.clock()
    while seixo.clock() - t < 0.3 do end
    os.execute("mkdir -p '" .. out .. "'")
  end
  local r = lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, seeds = {1}, maxeval = 2,
                          evaluate = function(mat) return {E = mat.modulus * 0.6} end, plot = false, print = false,
                          out = out .. "/calibration"}
  eq(r.evaluations, 2)
  if rank == 0 then os.execute("rm -rf '" .. out .. "'") end
end)

test("the models after a calibration are decomposed again", function()
  eq(seixo.decompose(), true)
  local m = seixo.model{dim = 2}
  eq(m:ranks(), 2)
  m:close()
end)
print(string.format("rank %d: %s | %s", rank, results[1] or "-", results[2] or "-"))
T.done()
