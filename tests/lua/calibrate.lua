-- lab.calibrate and seixo.optimize: the optimiser recovers known
-- parameters of a cheap synthetic material and of a tiny 2D specimen; runs
-- spread over worker processes; a killed calibration resumes from its log
-- without repeating a run; a failing run is recorded and the search goes on.
--
-- lab.calibrate with workers > 1 starts this script again in each worker
-- process (SEIXO_CALIBRATE_JOB set), which runs it up to the calibration it
-- serves: hence the calibrations that use processes come first, and the
-- logs are removed only by the parent.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local lab = require("seixo.lab")
local util = require("seixo.util")

local worker = os.getenv("SEIXO_CALIBRATE_JOB") ~= nil
local function fresh(path)
  if not worker then os.remove(path) end
  return path
end

-- The synthetic material: E with the modulus (and a little with the
-- stiffness ratio), nu with the stiffness ratio (not a power law), UCS with
-- the bond strength; each seed scatters them by a few per cent about the
-- law, with a mean of zero over the seeds 1, 2, 3.
local calls = 0
local function synthetic(material, seed)
  calls = calls + 1
  local s = seed - 2
  local kr = material.stiffness_ratio
  return {E = 1.1 * material.modulus * (1 + 0.1 / kr) * (1 + 0.02 * s),
          nu = (0.5 - 0.6 / (kr + 1)) * (1 - 0.03 * s),
          UCS = 1.3 * material.bond.tensile_strength * (1 + 0.04 * s)}
end
-- the targets of the known parameters modulus 50 GPa, stiffness ratio 2, strength 120 MPa
local known = {modulus = 50e9, stiffness_ratio = 2, strength = 120e6}
local targets = {E = 1.1 * 50e9 * 1.05, nu = 0.5 - 0.6 / 3, UCS = 1.3 * 120e6}
local bounds = {modulus = {10e9, 200e9}, stiffness_ratio = {1, 6}, strength = {30e6, 600e6}}

local function recovered(r, rel)
  for k, v in pairs(known) do near(r.parameters[k], v, rel) end
  near(r.material.bond.tensile_strength, known.strength, rel)
  -- the ratios of the BPM stay: the bond's modulus with the balls', cohesion with tensile strength
  near(r.material.bond.modulus, r.material.modulus, 1e-12)
  near(r.material.bond.cohesion, r.material.bond.tensile_strength, 1e-12)
end

test("seixo.optimize: BOBYQA and Nelder-Mead find a bounded minimum; f's error comes through", function()
  for _, alg in ipairs({"bobyqa", "neldermead", "sbplx"}) do
    local x, f, info = seixo.optimize(function(x) return (x[1] - 1.5) ^ 2 + 10 * (x[2] + 0.25) ^ 2 end,
                                      {x0 = {0, 0}, lower = {-2, -2}, upper = {2, 2}, algorithm = alg, maxeval = 500,
                                       xtol = 1e-10})
    near(x[1], 1.5, 1e-4)
    near(x[2], -0.25, 1e-4)
    check(f < 1e-8 and info.evaluations <= 500, alg)
  end
  -- the minimum outside the box: the bound
  local x = seixo.optimize(function(x) return (x[1] - 5) ^ 2 end, {x0 = {0}, lower = {-1}, upper = {1}})
  near(x[1], 1, 1e-9)
  local n = 0
  T.raises(function() seixo.optimize(function(x) n = n + 1; if n == 3 then error("boom") end return x[1] ^ 2 end,
                                     {x0 = {0.5}, lower = {-1}, upper = {1}}) end, "boom")
  eq(n, 3, "f is not called after its error")
  T.raises(function() seixo.optimize(function() return 0 / 0 end, {x0 = {0}, lower = {-1}, upper = {1}}) end,
           "f returned nan")
  T.raises(function() seixo.optimize(function() return 1 end, {x0 = {3}, lower = {-1}, upper = {1}}) end,
           "outside its bounds")
  T.raises(function() seixo.optimize(function() return 1 end, {x0 = {0}, lower = {1}, upper = {-1}}) end,
           "must be below")
end)

test("synthetic material over 2 worker processes: the known parameters, every run in the log", function()
  local log = fresh("calibrate_processes.csv")
  local r = lab.calibrate{targets = targets, parameters = bounds, evaluate = synthetic, seeds = 3, workers = 2,
                          tolerance = 1e-3, maxeval = 60, log = log, out = "calibrate_processes", plot = false,
                          print = false}
  recovered(r, 1e-2)
  eq(calls, 0, "every run was made in a worker process")
  local csv = util.read_csv(log)
  -- one row per run: each distinct candidate once per seed (a candidate met again comes from the log)
  local distinct = {}
  for i = 1, csv.rows do
    eq(csv.columns.status[i], 1)
    local key = string.format("%.10g %.10g %.10g", csv.columns.modulus[i], csv.columns.stiffness_ratio[i],
                              csv.columns.strength[i])
    distinct[key] = (distinct[key] or 0) + 1
  end
  for key, n in pairs(distinct) do eq(n, 3, key) end
  -- the pilot's batch: the pilot (candidate 1) and its twin (candidate 2, kn/ks x 2)
  eq(csv.columns.candidate[4], 2)
  eq(csv.columns.stiffness_ratio[4], 5)
  check(csv.rows <= 3 * r.evaluations)
  -- the scatter over the seeds: E's law scatters by 2 % per seed (sd 2 % of the mean)
  near(r.achieved.E.sd / r.achieved.E.mean, 0.02, 1e-2)
  eq(r.achieved.E.n, 3)
end)

if worker then return end -- the worker processes stop here: what follows runs in-process

test("synthetic material: few evaluations thanks to the scalings; the table and the figure", function()
  calls = 0
  local lines = {}
  local r = lab.calibrate{targets = targets, parameters = bounds, evaluate = synthetic, seeds = 3, workers = 1,
                          tolerance = 1e-2, maxeval = 60, log = fresh("calibrate_serial.csv"), out = "calibrate_serial",
                          print = function(s) lines[#lines + 1] = s end}
  recovered(r, 2e-2)
  -- the pilot, its perturbed twin (nu's exponent) and the scaled guesses reach 1 %
  check(r.evaluations <= 6, "evaluations: " .. r.evaluations)
  eq(calls, 3 * r.evaluations)
  check(r.status == "tolerance", r.status)
  local text = table.concat(lines, "\n")
  check(text:find("calibrate #1:", 1, true) and text:find("micro-parameters:", 1, true), text)
  check(r.table:find("E%s+57.75 GPa"), r.table)
  local conv = util.read_csv("calibrate_serial_convergence.csv")
  eq(conv.rows, r.evaluations)
  if lab.have_gnuplot() then check(io.open("calibrate_serial_convergence.png", "rb"), "the convergence plot") end
end)

test("a failing run is recorded and skipped; a candidate with no run left costs the penalty", function()
  local failures = 0
  local failing = function(material, seed)
    if seed == 2 and failures < 3 then failures = failures + 1; error("the specimen went unstable") end
    if material.modulus > 150e9 then return {E = 0 / 0, nu = 0.3, UCS = 1e8} end -- not finite: failed
    return synthetic(material, seed)
  end
  local log = fresh("calibrate_failing.csv")
  local lines = {}
  local r = lab.calibrate{targets = targets, parameters = bounds, evaluate = failing, seeds = 3, workers = 1,
                          tolerance = 1e-3, maxeval = 60, log = log, out = "calibrate_failing", plot = false,
                          print = function(s) lines[#lines + 1] = s end}
  local csv = util.read_csv(log)
  local failed = 0
  for i = 1, csv.rows do if csv.columns.status[i] == 0 then failed = failed + 1 end end
  check(failed >= 3, "failed runs in the log: " .. failed)
  check(table.concat(lines, "\n"):find("the specimen went unstable", 1, true), "the failure is reported")
  recovered(r, 2e-2)
  -- all seeds failing: the penalty
  local p = lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = function() error("no") end,
                          seeds = 2, workers = 1, maxeval = 4, log = fresh("calibrate_penalty.csv"),
                          out = "calibrate_penalty", plot = false, print = false, penalty = 7}
  eq(p.objective, 7)
  eq(p.evaluations, 4)
end)

-- Runs that fail below 40 GPa, the target 10 GPa far below: every measured
-- candidate's objective is above the fixed penalty, so the first failed
-- candidate scored best, became the start of the guesses and of BOBYQA, and
-- was the result (objective 10, E "failed": a review's finding). A failed
-- candidate now costs more than any measured one, and the best is measured.
test("a failed candidate is never the best while a measured one exists", function()
  local r = lab.calibrate{targets = {E = 10e9}, parameters = {modulus = {5e9, 200e9}},
                          evaluate = function(material)
                            if material.modulus < 40e9 then error("unstable run") end
                            return {E = material.modulus}
                          end,
                          seeds = 1, workers = 1, maxeval = 8, log = fresh("calibrate_far.csv"), out = "calibrate_far",
                          plot = false, print = false}
  check(r.achieved.E and r.achieved.E.mean >= 40e9, "the result was measured: " .. tostring(r.parameters.modulus))
  local first = r.history[1]
  check(first.achieved.E, "the pilot was measured")
  check(r.objective < first.objective, string.format("better than the pilot: %g against %g", r.objective, first.objective))
  for _, h in ipairs(r.history) do
    if not h.achieved.E then check(h.objective > first.objective, "a failed candidate costs more than the pilot") end
  end
end)

test("an interrupted run (Ctrl-C, a scheduler's SIGTERM) ends the calibration, not logged as a failed run", function()
  -- it had been logged as failed (never run again on a restart) and the search went on
  local log = fresh("calibrate_interrupt.csv")
  local runs = 0
  raises(function()
    lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, seeds = 1, workers = 1, maxeval = 4,
                  log = log, out = "calibrate_interrupt", plot = false, print = false,
                  evaluate = function()
                    runs = runs + 1
                    os.execute("(sleep 0.2; kill -INT $PPID) &") -- (the shell's parent: this process)
                    local t = seixo.clock()
                    while seixo.clock() - t < 30 do end
                    return {E = 1e9}
                  end}
  end, "interrupted")
  eq(runs, 1)
  local f = io.open(log)
  if f then
    f:close()
    eq(util.read_csv(log).rows, 0, "no run logged")
  end
end)

test("a calibration killed in the middle resumes from its log without repeating a run", function()
  local log = fresh("calibrate_resume.csv")
  local script = os.tmpname()
  local f = assert(io.open(script, "w"))
  f:write(string.format([[
local lab = require("seixo.lab")
local kill_at, n = tonumber(os.getenv("KILL_AT")), 0
local function synthetic(material, seed)
  n = n + 1
  if n == kill_at then os.exit(9) end -- a hard stop in the middle of a run
  local h = io.open(%q, "a")
  h:write(material.modulus, " ", material.stiffness_ratio, " ", material.bond.tensile_strength, " ", seed, "\n")
  h:close()
  local kr = material.stiffness_ratio
  return {E = 1.1 * material.modulus * (1 + 0.1 / kr) * (1 + 0.02 * (seed - 2)), nu = 0.5 - 0.6 / (kr + 1),
          UCS = 1.3 * material.bond.tensile_strength}
end
local r = lab.calibrate{targets = {E = %.17g, nu = 0.3, UCS = 156e6}, parameters = {modulus = {10e9, 200e9},
  stiffness_ratio = {1, 6}, strength = {30e6, 600e6}}, evaluate = synthetic, seeds = 2, workers = 1,
  tolerance = 1e-3, maxeval = 40, log = %q, out = %q, plot = false}
print(string.format("RESULT %%.10g %%.10g %%.10g %%d", r.parameters.modulus, r.parameters.stiffness_ratio,
                    r.parameters.strength, r.evaluations))
]], log .. ".runs", 1.1 * 50e9 * 1.05, log, log:gsub("%.csv$", "")))
  f:close()
  os.remove(log .. ".runs")
  local status, out = T.run("'" .. script .. "'", nil)
  eq(status, 0, out)
  local whole = out:match("RESULT ([^\n]+)")
  local runs = 0
  for _ in io.lines(log .. ".runs") do runs = runs + 1 end
  -- again, killed at the 9th run, then resumed
  os.remove(log)
  os.remove(log .. ".runs")
  local p = io.popen("KILL_AT=9 timeout 120 " .. T.quote(T.seixo) .. " " .. T.quote(script) .. " 2>&1")
  local killed_out = p:read("a")
  local _, _, code = p:close()
  eq(code, 9, killed_out)
  local before = 0
  for _ in io.lines(log .. ".runs") do before = before + 1 end
  eq(before, 8, "runs before the kill")
  eq(util.read_csv(log).rows, 8, "the log holds every finished run")
  status, out = T.run("'" .. script .. "'")
  eq(status, 0, out)
  eq(out:match("RESULT ([^\n]+)"), whole, "the resumed calibration ends where the whole one did")
  local total, seen, repeated = 0, {}, 0
  for line in io.lines(log .. ".runs") do
    total = total + 1
    if seen[line] then repeated = repeated + 1 end
    seen[line] = true
  end
  eq(total, runs, "the two parts made as many runs as the whole calibration")
  eq(repeated, 0, "no run repeated")
  check(out:find("from the log", 1, true), out)
  os.remove(script)
end)

test("the log's columns hold their targets' values when targets before them are not measured", function()
  -- (UCS and BTS alone: written in turn, they filled E's and nu's columns,
  -- and a resumed calibration read no BTS: every run failed)
  local log = fresh("calibrate_columns.csv")
  local function strengths(material)
    return {UCS = 1.3 * material.bond.tensile_strength, BTS = 0.2 * material.bond.tensile_strength}
  end
  local function run()
    return lab.calibrate{targets = {UCS = 200e6, BTS = 30e6}, parameters = {strength = {50e6, 400e6}},
                         evaluate = strengths, seeds = {1}, workers = 1, maxeval = 3, log = log,
                         out = log:gsub("%.csv$", ""), plot = false, print = false}
  end
  local first = run()
  local csv = util.read_csv(log)
  eq(csv.columns.E[1], nil)
  eq(csv.columns.nu[1], nil)
  near(csv.columns.UCS[1], 1.3 * 157e6, 1e-9)
  near(csv.columns.BTS[1], 0.2 * 157e6, 1e-9)
  local again = run() -- every run from the log
  eq(again.objective, first.objective)
  eq(again.achieved.BTS.mean, first.achieved.BTS.mean)
end)

test("a log made with another material, specimen or test is refused, naming what differs", function()
  -- (a 2D calibration at friction 0.5, then 0.9 with the same log, took
  -- the second's runs "from the log" of the first: a silent wrong result)
  local log = fresh("calibrate_settings.csv")
  local function run(over)
    local o = {targets = {E = 60e9}, parameters = {modulus = {10e9, 200e9}}, material = {friction = 0.5},
               evaluate = synthetic, seeds = {1}, workers = 1, maxeval = 2, log = log,
               out = log:gsub("%.csv$", ""), plot = false, print = false}
    for k, v in pairs(over) do o[k] = v end
    return lab.calibrate(o)
  end
  run{}
  local f = io.open(log .. ".settings")
  check(f and f:read("a"):find("material.friction = 0.5\n", 1, true), "the settings beside the log")
  if f then f:close() end
  local err = raises(function() run{material = {friction = 0.9}} end,
                     "lab.calibrate: the log " .. log .. " holds runs made with other settings (material.friction 0.5 "
                     .. "in the log, 0.9 now; see " .. log .. ".settings): delete the log or give another path")
  check(err:find("^[^\n]*calibrate%.lua:%d+:") and not err:find("seixo/", 1, true), "at the caller's line: " .. err)
  -- a target's value only weighs the logged runs: they serve another value
  local lines = {}
  run{targets = {E = 70e9}, print = function(s) lines[#lines + 1] = s end}
  check(lines[1]:find("from the log", 1, true), lines[1])
  -- which targets are measured chooses the tests (and a run lacking one failed)
  raises(function() run{targets = {E = 60e9, UCS = 150e6}} end, 'targets "E" in the log, "E UCS" now')
  -- the lab's recipe: a specimen too small for its balls fails at once, its run logged as failed
  local recipe = {dim = 2, width = 0.001, height = 0.002, radius = {0.4e-3, 0.6e-3}}
  local lab_log = fresh("calibrate_settings_lab.csv")
  local function lab_run(specimen, test)
    return lab.calibrate{targets = {E = 60e9}, parameters = {modulus = {10e9, 200e9}}, specimen = specimen,
                         test = test, seeds = {1}, workers = 1, maxeval = 1, log = lab_log,
                         out = lab_log:gsub("%.csv$", ""), plot = false, print = false}
  end
  lab_run(recipe)
  eq(util.read_csv(lab_log).columns.status[1], 0, "the run failed")
  raises(function() lab_run({dim = 2, width = 0.002, height = 0.002, radius = {0.4e-3, 0.6e-3}}) end,
         "(specimen.width 0.001 in the log, 0.002 now; see")
  raises(function() lab_run(recipe, {strain_rate = 1}) end, "(test.strain_rate unset in the log, 1 now; see")
  -- a log without its settings (an older seixo's) cannot be told apart: refused
  os.remove(log .. ".settings")
  raises(function() run{} end, "the log " .. log .. " has no settings file " .. log .. ".settings")
end)

test("a tiny 2D specimen: the modulus that gives a known E is recovered", function()
  local recipe = {dim = 2, width = 0.012, height = 0.024, radius = {0.6e-3, 1e-3}}
  local path = os.tmpname()
  local spec = lab.specimen{dim = 2, width = 0.012, height = 0.024, radius = {0.6e-3, 1e-3}, seed = 1, path = path,
                            log = false, material = lab.rock{modulus = 40e9, bond = {modulus = 40e9}}}
  local known = lab.ucs(spec, {log = false})
  os.remove(path)
  -- the measured curve: ten points of the known test's rise to 60 % of its
  -- peak (nearer the peak, where the cracks come, the curve of a packing
  -- made with 40.01 GPa is another curve: the genesis depends on the
  -- modulus, chaotically)
  local curve, peak, last = {strain = {}, stress = {}}, 1, 1
  for i, row in ipairs(known.rows) do if row[8] > known.rows[peak][8] then peak = i end end
  for i = 1, peak do if known.rows[i][8] <= 0.6 * known.rows[peak][8] then last = i end end
  for k = 1, 10 do
    local row = known.rows[math.max(1, math.floor(last * k / 10))]
    curve.strain[k], curve.stress[k] = row[3], row[8]
  end
  local lines = {}
  local r = lab.calibrate{targets = {E = known.young, curve = curve}, parameters = {modulus = {10e9, 200e9, 80e9}},
                          specimen = recipe,
                          seeds = {1}, workers = 1, tolerance = 1e-2, maxeval = 8, log = fresh("calibrate_2d.csv"),
                          out = "calibrate_2d", plot = false, print = function(s) lines[#lines + 1] = s end}
  -- within the genesis' chaotic scatter (below: E by 2-3 % for a 0.5 %
  -- change of the modulus; a search met its tolerance at 40.88 GPa, E
  -- +0.5 %, after 40.19 GPa had given E -1.7 %)
  check(math.abs(r.parameters.modulus / 40e9 - 1) < 0.03, table.concat(lines, "\n"))
  -- E goes as the modulus: the first step from 80 GPa lands within 2 %
  -- of 40 GPa (it did in two evaluations, before a change of the loading
  -- path: each candidate's genesis depends on its modulus chaotically, E
  -- by about 2 % for a 0.5 % change, so the search then wanders within
  -- that scatter until the tolerance, 1e-2 on the objective, is met)
  eq(r.history[1].parameters.modulus, 80e9)
  check(math.abs(r.history[2].parameters.modulus / 40e9 - 1) < 0.02, table.concat(lines, "\n"))
  check(r.achieved.nu and r.achieved.UCS, "every macro-property of the test is reported")
  -- the curve's misfit: 80 GPa (the start) is far off, the result close.
  -- Close is within the genesis' chaotic scatter (above: E by 2-3 % for a
  -- 0.5 % change of the modulus), which moves the curve as much: candidates
  -- at 40.2 GPa gave 0.015 and 0.020 (the objective weighs E's error too),
  -- and 0.01 held only while the search happened on a luckier packing
  check(r.history[1].achieved.curve.mean > 0.2, "misfit at the start " .. r.history[1].achieved.curve.mean)
  check(r.achieved.curve.mean < 0.03, "misfit at the end " .. r.achieved.curve.mean .. "\n" .. table.concat(lines, "\n"))
end)

test("a tiny 2D specimen: BTS (a disk), c and phi (a series) are measured for their targets", function()
  local r = lab.calibrate{targets = {BTS = 20e6, c = 30e6, phi = 30}, parameters = {strength = {50e6, 400e6}},
                          specimen = {dim = 2, width = 0.012, height = 0.024, radius = {0.6e-3, 1e-3}},
                          confining = {0, 5e6}, seeds = {1}, workers = 1, maxeval = 1, -- (the disk: the width)
                          log = fresh("calibrate_2d_strengths.csv"), out = "calibrate_2d_strengths", plot = false,
                          print = false}
  eq(r.evaluations, 1)
  for _, k in ipairs({"BTS", "c", "phi", "UCS", "E"}) do
    local a = r.achieved[k]
    check(a and a.n == 1 and a.mean > 0 and a.mean < math.huge, k)
  end
  check(r.achieved.BTS.mean < r.achieved.UCS.mean, "tensile strength below the UCS")
end)

test("bad options are clear errors at the caller", function()
  -- issue 18's fuzzer: a string for maxeval failed deep in the search with Lua's own message
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    maxeval = "zz"} end, "lab.calibrate: maxeval must be a whole number >= 0 (got zz)")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    tolerance = 0 / 0} end, "lab.calibrate: tolerance must be a finite number >= 0")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    print = math.mininteger} end, "lab.calibrate: print must be a function or false (got number)")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {2e9, 1e9}}, evaluate = synthetic} end,
           "parameters.modulus must be {lower, upper}")
  -- a granular specimen: refused up front, not run to fail every evaluation (a review's finding)
  T.raises(function() lab.calibrate{targets = {E = 1e8}, parameters = {modulus = {1e8, 1e9}},
                                    specimen = {dim = 2, width = 0.01, height = 0.02, bonds = false}} end,
           "a granular specimen (specimen.bonds = false) is not calibrated here")
  -- the long fuzz run (issue 18): a list for parameters and a function for out failed inside calibrate.lua
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {1, 2, 3, 4}, evaluate = synthetic} end,
           "lab.calibrate: parameters must be keyed by name, {modulus = {lower, upper}, ...} (got a number key: 1)")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {{}}, evaluate = synthetic} end,
           "parameters must be keyed by name")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    out = print} end, "lab.calibrate: out must be a path (a string; got function)")
  -- and a list of seeds holding a table failed writing its log
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    seeds = {{}}} end, "lab.calibrate: seeds[1] must be a whole number, not a table")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    seeds = {1, 0.5}} end, "seeds[2] must be a whole number, not 0.5")
  T.raises(function() lab.calibrate{targets = {G = 1}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic} end,
           "unknown target 'G'")
  -- a unit slipped (50 meant as GPa), a ratio that no material has: before hours of runs
  T.raises(function() lab.calibrate{targets = {E = 50}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic} end,
           "lab.calibrate: targets.E = 50 is outside 100000 ... 1e+12 Pa (seixo's unit is the pascal")
  T.raises(function() lab.calibrate{targets = {E = 1e9, nu = 0.7}, parameters = {modulus = {1e9, 2e9}},
                                    evaluate = synthetic} end, "targets.nu = 0.7 is outside")
  -- an output folder that is not there, found before the runs
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}, evaluate = synthetic,
                                    out = "no/such/folder/cal"} end,
           "lab.calibrate: cannot write no/such/folder/cal.csv: No such file or directory")
  -- the Brazilian disk of a cylinder's recipe: its diameter, half as thick
  -- (a rect's recipe: its width); a recipe with neither names what to give
  T.raises(function() lab.calibrate{targets = {BTS = 1e7}, parameters = {strength = {1e7, 2e7}},
                                    specimen = {dim = 3, shape = "prism", depth = 0.01, height = 0.02}} end,
           "the Brazilian disk needs a diameter: brazilian = {diameter = ...}")
  T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {nothing = {1, 2}}, evaluate = synthetic} end,
           "parameter 'nothing'")
  T.raises(function() lab.calibrate{targets = {c = 1e6}, parameters = {cohesion = {1e6, 2e6}}, specimen = {}} end,
           "confining")
  local err = T.raises(function() lab.calibrate{targets = {E = 1e9}, parameters = {modulus = {1e9, 2e9}}} end,
                       "specimen =")
  check(err:find("calibrate.lua:%d+:"), "the position is the caller's: " .. err)
end)

T.done()
