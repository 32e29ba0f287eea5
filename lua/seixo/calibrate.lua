-- seixo.calibrate: lab.calibrate, the search for the micro-parameters of a
-- bonded-particle material that reproduce a rock's macro-properties (seed
-- 4.4: no formula links the two, so the lab tests are run until they agree).
--   local r = lab.calibrate{targets = {E = 69e9, nu = 0.26, UCS = 200e6},
--                           parameters = {modulus = {20e9, 150e9}, stiffness_ratio = {1, 5},
--                                         strength = {50e6, 500e6}},
--                           specimen = {dim = 2, width = 0.025, height = 0.05}, seeds = 2}
--
-- How it converges in few evaluations: the BPM's known scalings. E grows in
-- proportion to the moduli at fixed ratios (Ec with the bond's), the
-- strengths (UCS, BTS, c) in proportion to the bond strengths, and nu with
-- the stiffness ratios (kn/ks and the bond's) by a law that is not a power:
-- its local exponent comes from a second candidate, perturbed, evaluated
-- beside the first (the pilot), and again between guesses. Each free
-- parameter is then scaled to its target (x = x0 (target /
-- achieved)^(1/exponent), a factor of 2 at most), a few times, and NLopt's
-- BOBYQA polishes the result in log-scaled parameters against normalised
-- targets (sum of squared relative errors).
--
-- Noise: every candidate is tested on the same few specimens (seeds), so the
-- objective is the same function of the parameters at every call (common
-- random numbers), and each macro-property is reported as mean and scatter.
--
-- Parallel: the runs of a batch (candidates x seeds) go to separate
-- processes, the running script started again by seixo.executable() with
-- SEIXO_CALIBRATE_JOB naming a job file; that process runs the script up to
-- this call, which runs the one job, writes its result and exits. Under
-- mpirun every rank runs the script too: rank 0 searches and the others
-- wait here for jobs (seixo.send/receive), and all return the same result.
-- Hence the rule for a script: what comes before lab.calibrate must be cheap
-- and the same on every run.
--
-- Robust: a run that raises an error, goes unstable (a result that is not a
-- finite number) or stops before its peak is recorded as failed; a
-- candidate without a successful run costs a penalty and the search goes
-- on. Every run is logged (a CSV rewritten atomically, one row per run),
-- and a calibration started again reads its log first: the search is
-- deterministic, so it passes through the same candidates, finds their runs
-- in the log and only runs what the log lacks. What else a run's result
-- depends on (the base material, the specimen's recipe, the tests) is kept
-- beside the log (log .. ".settings"): a log made with other settings is
-- refused, not read as this calibration's runs.

local util = require("seixo.util")
local pool = require("seixo.pool")

local M = {}

local macros = {"E", "nu", "UCS", "BTS", "c", "phi", "curve"}
local is_macro = {}
for _, k in ipairs(macros) do is_macro[k] = true end
-- how each macro-property is shown: a divisor and a unit
local units = {E = {1e9, "GPa"}, UCS = {1e6, "MPa"}, BTS = {1e6, "MPa"}, c = {1e6, "MPa"}, nu = {1, ""},
               phi = {1, "deg"}, curve = {1, ""}}

-- An error at the first caller outside this file: the user's script.
local here = debug.getinfo(1, "S").source
local function fail(fmt, ...)
  local level = 2
  -- (and past a C function: the pcall of a search under mpirun)
  while debug.getinfo(level, "S") and (debug.getinfo(level, "S").source == here or debug.getinfo(level, "S").what == "C") do
    level = level + 1
  end
  error(string.format("lab.calibrate: " .. fmt, ...), level)
end

local copy = require("seixo.lab.tables").copy
local polling = require("seixo.lab.polling").run -- fn(...) while handing out work
local gnuplot = require("seixo.lab.plots").gnuplot -- (the figures of the lab look the same)

-- ------------------------------------------------------- the parameters

-- A free parameter's effect on the material: named groups keep the BPM's
-- ratios (the bond's modulus with the balls', cohesion with tensile
-- strength, each standard deviation with its mean); any other name is a
-- dotted path into the material ("bond.radius_multiplier", "damping").
-- role: the targets it scales, first choice first; exponent: the power law
-- of that scaling when known (nil: measured by the pilot).
local function scale_fields(t, f, keys)
  for _, k in ipairs(keys) do if t[k] then t[k] = t[k] * f end end
end

local groups = {
  modulus = {role = {"E"}, exponent = 1, get = function(m) return m.modulus end,
             set = function(m, v) local f = v / m.modulus; m.modulus = v; scale_fields(m.bond, f, {"modulus"}) end},
  stiffness_ratio = {role = {"nu"}, get = function(m) return m.stiffness_ratio end,
                     set = function(m, v)
                       local f = v / m.stiffness_ratio
                       m.stiffness_ratio = v
                       scale_fields(m.bond, f, {"stiffness_ratio"})
                     end},
  strength = {role = {"UCS", "BTS", "c"}, exponent = 1, get = function(m) return m.bond.tensile_strength end,
              set = function(m, v)
                scale_fields(m.bond, v / m.bond.tensile_strength,
                             {"tensile_strength", "tensile_strength_sd", "cohesion", "cohesion_sd"})
              end},
  tensile_strength = {role = {"BTS"}, exponent = 1, get = function(m) return m.bond.tensile_strength end,
                      set = function(m, v)
                        scale_fields(m.bond, v / m.bond.tensile_strength, {"tensile_strength", "tensile_strength_sd"})
                      end},
  cohesion = {role = {"c", "UCS"}, exponent = 1, get = function(m) return m.bond.cohesion end,
              set = function(m, v) scale_fields(m.bond, v / m.bond.cohesion, {"cohesion", "cohesion_sd"}) end},
  friction = {role = {"phi"}, get = function(m) return m.friction end, set = function(m, v) m.friction = v end},
}

-- The group of a parameter name: a named one, or a path into the material.
local function group_of(name, material)
  if groups[name] then return groups[name] end
  local keys = {}
  for k in name:gmatch("[^.]+") do keys[#keys + 1] = k end
  local function parent(m)
    for i = 1, #keys - 1 do m = type(m) == "table" and m[keys[i]] or nil end
    return type(m) == "table" and m or nil
  end
  local p = parent(material)
  if not p or type(p[keys[#keys]]) ~= "number" then
    local named = {}
    for k in pairs(groups) do named[#named + 1] = k end
    table.sort(named)
    fail("parameter '%s' is neither %s nor a number of the material", name, table.concat(named, ", "))
  end
  return {role = {}, get = function(m) return parent(m)[keys[#keys]] end,
          set = function(m, v) parent(m)[keys[#keys]] = v end}
end

-- Ten significant digits: the value a run is made with is the value the log
-- keeps, so a run read back from the log is the same run.
local function quantize(v) return tonumber(string.format("%.10g", v)) end

-- messages and files between processes (seixo.pool)
local quote = pool.quote

-- ------------------------------------------------------ the evaluation

-- The stress of a measured curve's point against the simulated curve
-- (axial strain, deviator): the relative rms misfit, over the peak of the
-- measured curve. Past the end of the simulation the last stress counts.
local function curve_misfit(curve, rows)
  local peak, sum = 0, 0
  for _, s in ipairs(curve.stress) do peak = math.max(peak, math.abs(s)) end
  for i, e in ipairs(curve.strain) do
    local sim = rows[#rows][8]
    for j = 2, #rows do
      if rows[j][3] >= e then
        local a, b = rows[j - 1], rows[j]
        local t = b[3] > a[3] and (e - a[3]) / (b[3] - a[3]) or 1
        sim = a[8] + t * (b[8] - a[8])
        break
      end
    end
    sum = sum + ((sim - curve.stress[i]) / peak) ^ 2
  end
  return math.sqrt(sum / #curve.strain)
end

-- The lab's own evaluation: a specimen made with the material and seed,
-- its UCS test (or, for c and phi, the series), and for BTS a disk and its
-- Brazilian test.
local function lab_evaluate(lab, o, material, seed)
  local t = o.targets
  local base = os.tmpname()
  local files = {base}
  local function cleanup() for _, f in ipairs(files) do os.remove(f) end end
  local ok, out = pcall(function()
    local recipe = copy(o.specimen)
    recipe.material, recipe.seed, recipe.log = material, seed, false
    recipe.path = base .. ".h5"
    files[#files + 1] = recipe.path
    local values = {}
    local function peaked(r, what)
      if r.stopped ~= "post_peak" then error(string.format("%s stopped on %s before its peak", what, r.stopped), 0) end
      return r
    end
    if t.E or t.nu or t.UCS or t.curve or t.c or t.phi then
      local spec = lab.specimen(recipe)
      local test = copy(o.test or {})
      test.log = false
      local r
      if t.c or t.phi then
        test.confining = o.confining
        -- the runs already fill the cores: the series' tests in turn
        if o.workers > 1 then test.jobs = test.jobs or 1 end
        local s = lab.series(spec, test)
        for i, x in ipairs(s.tests) do
          peaked(x, string.format("the test at confining %g Pa", o.confining[i]))
          if x.confining == 0 then r = x end
        end
        values.c, values.phi = s.fit.c, s.fit.phi
      else
        r = peaked(lab.ucs(spec, test), "the UCS test")
      end
      if r then
        values.E, values.nu, values.UCS = r.young, r.poisson, r.peak
        if t.curve then values.curve = curve_misfit(t.curve, r.rows) end
      end
    end
    if t.BTS then
      local disk = copy(o.disk)
      disk.material, disk.seed, disk.log = material, seed, false
      disk.path = base .. "_disk.h5"
      files[#files + 1] = disk.path
      local b = peaked(lab.brazilian(lab.specimen(disk), {log = false}), "the Brazilian test")
      -- a disk that gave way at the platens measured no tensile strength
      if b.gave_way then error("the Brazilian test: " .. b.warnings[1], 0) end
      values.BTS = b.tensile_strength
    end
    return values
  end)
  cleanup()
  if not ok then error(out, 0) end
  return out
end

-- One run, protected: {status = 1, values = {...}} or {status = 0, error = why}.
local function run_job(o, x, seed)
  local t0 = seixo.clock()
  local interrupts = seixo.interrupts()
  local ok, values = pcall(o.evaluate, o.material_of(x), seed)
  -- an interrupt (Ctrl-C, a scheduler's SIGTERM) ends the calibration: as
  -- a failed run it went into the log, was never run again, and the
  -- search went on
  if not ok and seixo.interrupts() > interrupts then error(values, 0) end
  if ok and type(values) ~= "table" then ok, values = false, "evaluate returned " .. type(values) end
  if ok then
    for _, k in ipairs(o.target_names) do
      local v = values[k]
      if type(v) ~= "number" or v ~= v or v == math.huge or v == -math.huge then
        ok, values = false, string.format("%s is %s: not measured, or the run went unstable", k, tostring(v))
        break
      end
    end
  end
  local rec = {status = ok and 1 or 0, time = seixo.clock() - t0}
  if ok then
    rec.values = {}
    for k, v in pairs(values) do if is_macro[k] and type(v) == "number" then rec.values[k] = quantize(v) end end
  else
    rec.error = tostring(values)
  end
  return rec
end

-- ------------------------------------------------------ running batches

-- The script's command line, to start it again as a worker (nil when there
-- is no script file: an -e chunk, the standard input or the REPL).
local function script_command()
  if type(arg) ~= "table" or not arg[0] or arg[0] == "-" then return nil end
  local lo = 0
  while arg[lo - 1] do lo = lo - 1 end
  local parts = {quote(seixo.executable())}
  for i = lo + 1, #arg do parts[#parts + 1] = quote(arg[i]) end
  return table.concat(parts, " ")
end

-- Runs jobs {x =, seed =} in processes, `workers` at a time (seixo.pool),
-- each the script started again with SEIXO_CALIBRATE_JOB naming its job.
-- A process that dies without answering is a failed run.
local function run_processes(o, jobs, record)
  local command = script_command()
  local files = {}
  for i, j in ipairs(jobs) do files[i] = {log = o.log, x = j.x, seed = j.seed} end
  pool.run{jobs = files, workers = o.workers, prefix = o.log,
           command = function(job_file) return string.format("SEIXO_CALIBRATE_JOB=%s %s", quote(job_file), command) end,
           done = function(i, rec, output, code)
             if type(rec) ~= "table" then
               local tail = output:sub(-300):gsub("%s+$", "")
               rec = {status = 0, time = 0, error = string.format("the worker exited with code %s: %s", tostring(code),
                                                                  tail)}
             end
             record(i, rec)
           end}
end

-- Runs jobs over the MPI ranks (pool.hand_out: rank 0 runs jobs too,
-- handing out meanwhile to the ranks that end, every few hundred steps of
-- the lab's models: lab's polling); record(i, rec) as the records come.
local function run_ranks(o, jobs, record)
  local ok, err = pool.hand_out{
    more = function(i) return i <= #jobs end,
    message = function(i) return {i = i, x = jobs[i].x, seed = jobs[i].seed} end,
    own = function(i, poll) return {i = i, rec = polling(poll, run_job, o, jobs[i].x, jobs[i].seed)} end,
    record = function(msg) record(msg.i, msg.rec) end}
  if not ok then error(err, 0) end
end

-- A rank other than 0: runs the jobs rank 0 sends until it sends the result.
local function serve_rank(o)
  return pool.serve_rank(function(msg) return {i = msg.i, rec = run_job(o, msg.x, msg.seed)} end)
end

-- ------------------------------------------------------------------ log

local function key_of(x, seed)
  local parts = {}
  for i, v in ipairs(x) do parts[i] = string.format("%.10g", v) end
  parts[#parts + 1] = tostring(seed)
  return table.concat(parts, " ")
end

local function log_header(o)
  local h = {"candidate", "seed", "status", "time"}
  for _, n in ipairs(o.names) do h[#h + 1] = n end
  for _, k in ipairs(macros) do h[#h + 1] = k end
  return h
end

-- A number as the shortest text that reads back as the same number.
local function exact(v)
  local s
  for digits = 15, 17 do
    s = string.format("%." .. digits .. "g", v)
    if tonumber(s) == v then break end
  end
  return s
end

-- What a run's result depends on besides its parameters and seed, as
-- "key = value" lines (sorted): the base material (a free parameter scales
-- the fields of its group from it), and when the lab evaluates, the
-- specimen's recipe, the test's options, the series' confining stresses
-- and the Brazilian disk's recipe, less what each run sets itself (seed,
-- material, path, log); and which targets are measured (they choose the
-- tests, and a run lacking one failed) with a curve's points. A target's
-- value is not among them: it only weighs the logged results, so a log
-- serves a calibration to another value.
local function settings_of(o, lab_evaluates)
  local lines = {}
  local function put(key, v)
    if type(v) == "table" then
      for k, x in pairs(v) do put(math.type(k) == "integer" and key .. "[" .. k .. "]" or key .. "." .. tostring(k), x) end
    elseif type(v) == "number" then
      lines[#lines + 1] = key .. " = " .. exact(v)
    elseif type(v) == "string" then
      lines[#lines + 1] = key .. " = " .. string.format("%q", v):gsub("\\\n", "\\n")
    elseif v ~= nil then
      lines[#lines + 1] = key .. " = " .. (type(v) == "boolean" and tostring(v) or "a " .. type(v))
    end
  end
  local function without_run(t)
    local r = copy(t or {})
    r.seed, r.material, r.path, r.log = nil, nil, nil, nil
    return r
  end
  put("material", o.material)
  put("targets", table.concat(o.target_names, " "))
  put("targets.curve", o.targets.curve)
  if lab_evaluates then
    put("specimen", without_run(o.specimen))
    put("test", without_run(o.test))
    if o.targets.c or o.targets.phi then put("confining", o.confining) end
    if o.disk then put("brazilian", without_run(o.disk)) end
  end
  table.sort(lines)
  return lines
end

local function settings_path(o) return o.log .. ".settings" end

-- Fails unless the log's settings file holds this calibration's settings,
-- naming the first that differ.
local function check_settings(o)
  local f = io.open(settings_path(o), "r")
  if not f then
    fail("the log %s has no settings file %s (an older seixo's log, or the file was removed): its runs may have "
         .. "been made with another material, specimen or test; delete the log or give another path (log = ...)",
         o.log, settings_path(o))
  end
  local logged, now = {}, {}
  for line in f:lines() do
    local k, v = line:match("^([^#].-) = (.*)$")
    if k then logged[k] = v end
  end
  f:close()
  for _, line in ipairs(o.settings) do
    local k, v = line:match("^(.-) = (.*)$")
    now[k] = v
  end
  local keys = {}
  for k in pairs(now) do if logged[k] ~= now[k] then keys[#keys + 1] = k end end
  for k in pairs(logged) do if now[k] == nil then keys[#keys + 1] = k end end
  if #keys == 0 then return end
  table.sort(keys)
  local differ = {}
  for i = 1, math.min(3, #keys) do
    local k = keys[i]
    differ[i] = string.format("%s %s in the log, %s now", k, logged[k] or "unset", now[k] or "unset")
  end
  if #keys > 3 then differ[#differ + 1] = string.format("and %d more", #keys - 3) end
  fail("the log %s holds runs made with other settings (%s; see %s): delete the log or give another path (log = ...)",
       o.log, table.concat(differ, "; "), settings_path(o))
end

-- Writes the settings file of a new log (before its first run).
local function write_settings(o)
  pool.write_file(settings_path(o), string.format("# lab.calibrate: what the runs logged in %s depend on besides "
                  .. "their parameters and seed\n%s\n", o.log, table.concat(o.settings, "\n")))
end

-- The runs of an earlier start of this calibration: key -> record; nil
-- when there is no log yet.
local function read_log(o)
  local cache, rows = {}, {}
  local f = io.open(o.log, "r")
  if not f then return nil end
  f:close()
  local csv = util.read_csv(o.log)
  local header = log_header(o)
  if table.concat(csv.header, ",") ~= table.concat(header, ",") then
    fail("the log %s has the columns %s, not this calibration's %s; remove it or name another log", o.log,
         table.concat(csv.header, ","), table.concat(header, ","))
  end
  check_settings(o)
  for i = 1, csv.rows do
    local x = {}
    for j, n in ipairs(o.names) do x[j] = csv.columns[n][i] end
    local rec = {status = csv.columns.status[i], time = csv.columns.time[i], values = {}}
    for _, k in ipairs(macros) do rec.values[k] = csv.columns[k][i] end
    if rec.status ~= 1 then rec.values, rec.error = nil, "failed (in the log)" end
    local row = {}
    for j, h in ipairs(header) do row[j] = csv.columns[h][i] end
    rows[#rows + 1] = row
    cache[key_of(x, csv.columns.seed[i])] = rec
  end
  return cache, rows
end

-- ------------------------------------------------------------- summary

-- A candidate from its runs: every macro-property's mean, scatter and
-- count, and the objective: the weighted sum of squared relative errors of
-- the means (a curve's misfit is already relative), or the penalty when a
-- target has no successful run.
local function summarize(o, x, recs)
  local lists, failed = {}, 0
  for _, rec in ipairs(recs) do
    if rec.status == 1 then
      for k, v in pairs(rec.values) do lists[k] = lists[k] or {}; table.insert(lists[k], v) end
    else
      failed = failed + 1
    end
  end
  local c = {x = x, achieved = {}, failed = failed, runs = #recs}
  for k, l in pairs(lists) do
    local mean, sd = util.mean_sd(l)
    c.achieved[k] = {mean = mean, sd = sd, n = #l}
  end
  local f, within = 0, true
  for _, k in ipairs(o.target_names) do
    local a = c.achieved[k]
    if not a then f = nil; break end
    local err = k == "curve" and a.mean or (a.mean - o.targets[k]) / math.abs(o.targets[k])
    f = f + (o.weights[k] or 1) * err * err
    within = within and math.abs(err) <= o.tolerance
  end
  c.objective = f and quantize(f) or o.penalty
  c.ok = f ~= nil
  c.within = c.ok and within -- every target within the tolerance: done
  return c
end

local function show(k, v)
  local u = units[k]
  return string.format("%.4g%s", v / u[1], u[2] ~= "" and " " .. u[2] or "")
end

local function progress(o, c, cached, seconds)
  local parts = {}
  for i, n in ipairs(o.names) do parts[#parts + 1] = string.format("%s %.4g", n, c.x[i]) end
  local got = {}
  for _, k in ipairs(o.target_names) do
    local a = c.achieved[k]
    if a then
      local err = k == "curve" and "" or string.format(" (%+.1f %%)", 100 * (a.mean / o.targets[k] - 1))
      got[#got + 1] = string.format("%s %s ± %s%s", k, show(k, a.mean), show(k, a.sd), err)
    else
      got[#got + 1] = k .. " failed"
    end
  end
  o.print(string.format("calibrate #%d: %s | %s | objective %.3g (%d runs, %d failed, %s)", c.index,
                        table.concat(parts, ", "), table.concat(got, ", "), c.objective, c.runs, c.failed,
                        cached and "from the log" or string.format("%.1f s", seconds)))
end

-- --------------------------------------------------------- the figures

local function write_convergence(o, history)
  local header = {"evaluation", "objective"}
  for _, k in ipairs(o.target_names) do header[#header + 1] = k end
  local rows = {}
  for i, c in ipairs(history) do
    local row = {i, c.objective}
    for j, k in ipairs(o.target_names) do
      local a = c.achieved[k]
      -- achieved over target (a curve: its misfit, whose target is 0)
      row[j + 2] = a and (k == "curve" and a.mean or a.mean / o.targets[k]) or nil
    end
    rows[i] = row
  end
  o.lab.write_csv(o.out .. "_convergence.csv", header, rows)
  if o.plot == false then return end
  local lines = {}
  for j, k in ipairs(o.target_names) do
    lines[#lines + 1] = string.format("'%s' using 1:%d with linespoints lw 2 title '%s%s'", o.out .. "_convergence.csv",
                                      j + 2, k, k == "curve" and " misfit" or " / target")
  end
  lines[#lines + 1] = string.format("'%s' using 1:2 axes x1y2 with linespoints dt 2 title 'objective'",
                                    o.out .. "_convergence.csv")
  local script = string.format([[
set terminal pngcairo size 900,600 font ',11'
set datafile separator ','
set grid
set output '@p@'
set title 'calibration: achieved / target against evaluations'
set xlabel 'evaluation (candidate)'
set ylabel 'achieved / target'
set y2label 'objective'
set logscale y2
set y2tics
set key outside bottom center horizontal
plot 1 lc rgb 'black' notitle, %s
]], table.concat(lines, ", "))
  gnuplot(script, {{key = "p", path = o.out .. "_convergence.png"}})
end

local function final_table(o, best)
  local lines = {string.format("%-8s %14s %28s %9s", "target", "wanted", "achieved (mean ± scatter, n)", "error")}
  for _, k in ipairs(o.target_names) do
    local a = best.achieved[k]
    local wanted = k == "curve" and "0" or show(k, o.targets[k])
    local got = a and string.format("%s ± %s (%d)", show(k, a.mean), show(k, a.sd), a.n) or "failed"
    local err = (a and k ~= "curve") and string.format("%+.1f %%", 100 * (a.mean / o.targets[k] - 1)) or ""
    lines[#lines + 1] = string.format("%-8s %14s %28s %9s", k, wanted, got, err)
  end
  for k, a in pairs(best.achieved) do
    if not o.targets[k] then
      lines[#lines + 1] = string.format("%-8s %14s %28s", k, "-", string.format("%s ± %s (%d)", show(k, a.mean),
                                                                                 show(k, a.sd), a.n))
    end
  end
  lines[#lines + 1] = "micro-parameters:"
  for i, n in ipairs(o.names) do lines[#lines + 1] = string.format("  %-18s %.6g", n, best.x[i]) end
  return table.concat(lines, "\n")
end

-- -------------------------------------------------------------- options

local option_keys = {"targets", "weights", "parameters", "material", "specimen", "test", "confining", "brazilian",
                     "seeds", "workers", "maxeval", "xtol", "tolerance", "algorithm", "guesses", "penalty", "log",
                     "out", "plot", "print", "evaluate"}

-- What a rock's or a grain's macro-property can be: a target outside is a
-- slip of the unit (E = 50 for 50 GPa), found before hours of runs.
local target_range = {
  E = {1e5, 1e12, "Pa", " (seixo's unit is the pascal: 50 GPa is 50e9)"},
  UCS = {1e3, 1e10, "Pa", " (seixo's unit is the pascal: 150 MPa is 150e6)"},
  BTS = {1e3, 1e10, "Pa", " (seixo's unit is the pascal: 10 MPa is 10e6)"},
  c = {1e3, 1e10, "Pa", " (seixo's unit is the pascal: 30 MPa is 30e6)"},
  nu = {-0.999, 0.499, "", " (a Poisson's ratio lies between -1 and 0.5)"},
  phi = {0.1, 89.9, "degrees", ""},
}

local function check_options(lab, opts)
  if type(opts) ~= "table" then fail("a table of options expected, got %s", type(opts)) end
  local allowed = {}
  for _, k in ipairs(option_keys) do allowed[k] = true end
  for k in pairs(opts) do
    if not allowed[k] then fail("unknown option '%s' (valid: %s)", tostring(k), table.concat(option_keys, ", ")) end
  end
  local o = {lab = lab, weights = opts.weights or {}, targets = {}, target_names = {}}
  if type(opts.targets) ~= "table" then fail("targets = {E =, nu =, UCS =, BTS =, c =, phi =, curve =} expected") end
  for _, k in ipairs(macros) do
    local v = opts.targets[k]
    if v ~= nil then
      if k == "curve" then
        if type(v) ~= "table" or type(v.strain) ~= "table" or type(v.stress) ~= "table" or #v.strain < 2
           or #v.strain ~= #v.stress then
          fail("targets.curve = {strain = {...}, stress = {...}} (axial strain, deviator [Pa]) of equal lengths >= 2")
        end
      elseif type(v) ~= "number" or v ~= v or v == 0 or math.abs(v) == math.huge then
        fail("targets.%s must be a finite non-zero number (got %s)", k, tostring(v))
      elseif target_range[k] and not (v >= target_range[k][1] and v <= target_range[k][2]) then
        local r = target_range[k]
        fail("targets.%s = %g is outside %g ... %g %s%s", k, v, r[1], r[2], r[3], r[4])
      end
      o.targets[k] = v
      o.target_names[#o.target_names + 1] = k
    end
  end
  for k in pairs(opts.targets) do
    if not is_macro[k] then fail("unknown target '%s' (valid: %s)", tostring(k), table.concat(macros, ", ")) end
  end
  if #o.target_names == 0 then fail("no target given") end
  if (o.targets.c or o.targets.phi) and not opts.evaluate
     and (type(opts.confining) ~= "table" or #opts.confining < 2) then
    fail("targets c and phi need a series: confining = {0, sigma3, ...}")
  end
  o.confining = opts.confining
  o.material = lab.rock(opts.material)
  if type(opts.parameters) ~= "table" or next(opts.parameters) == nil then
    fail("parameters = {name = {lower, upper}, ...} expected (names: modulus, stiffness_ratio, strength, ...)")
  end
  o.names, o.lower, o.upper, o.x0, o.groups = {}, {}, {}, {}, {}
  for name in pairs(opts.parameters) do
    if type(name) ~= "string" then
      fail("parameters must be keyed by name, {modulus = {lower, upper}, ...} (got a %s key: %s)", type(name),
           tostring(name))
    end
    o.names[#o.names + 1] = name
  end
  table.sort(o.names)
  for i, name in ipairs(o.names) do
    local b = opts.parameters[name]
    local g = group_of(name, o.material)
    if type(b) ~= "table" or type(b[1]) ~= "number" or type(b[2]) ~= "number" or not (b[1] < b[2]) then
      fail("parameters.%s must be {lower, upper} with lower < upper", name)
    end
    o.groups[i], o.lower[i], o.upper[i] = g, b[1], b[2]
    o.x0[i] = quantize(math.min(b[2], math.max(b[1], b[3] or g.get(o.material))))
  end
  function o.material_of(x)
    local m = copy(o.material)
    for i, g in ipairs(o.groups) do g.set(m, x[i]) end
    return m
  end
  if opts.evaluate ~= nil and type(opts.evaluate) ~= "function" then fail("evaluate must be a function") end
  if not opts.evaluate and type(opts.specimen) ~= "table" then
    fail("specimen = {dim =, width =, height =, ...} (lab.specimen's options) expected")
  end
  if not opts.evaluate and opts.specimen.bonds == false then -- its tests never pass a peak to the post_peak stop
    fail("a granular specimen (specimen.bonds = false) is not calibrated here: its compression tests load to "
         .. "max_strain, and E, nu, UCS and c, phi are read past a bonded specimen's peak; give evaluate = fn")
  end
  o.specimen, o.test = opts.specimen, opts.test
  if opts.brazilian ~= nil and type(opts.brazilian) ~= "table" then
    fail("brazilian must be a table of the disk's options (got %s)", type(opts.brazilian))
  end
  if o.targets.BTS and not opts.evaluate then
    -- the Brazilian disk: the recipe's balls and material, as wide as the
    -- specimen (its diameter or width) and, in 3D, half as thick (ISRM's
    -- t/D = 0.5) but at least the 5 largest radii lab.specimen needs,
    -- unless brazilian says otherwise
    local disk, dim = copy(opts.specimen), opts.specimen.dim or 3
    disk.width, disk.height, disk.depth, disk.thickness = nil, nil, nil, nil
    for k, v in pairs(opts.brazilian or {}) do disk[k] = v end
    disk.shape = dim == 3 and "disc" or "disk"
    disk.diameter = disk.diameter or opts.specimen.diameter or opts.specimen.width
    if type(disk.diameter) ~= "number" or not (disk.diameter > 0) then
      fail("the Brazilian disk needs a diameter: brazilian = {diameter = ...} (m)")
    end
    if dim == 3 and not disk.thickness then
      -- (of clumps: their radii come from the template; 1.33e-3: lab.specimen's default rmax)
      local rmax = disk.clump and 0 or type(disk.radius) == "table" and disk.radius[2] or 1.33e-3
      disk.thickness = math.max(0.5 * disk.diameter, type(rmax) == "number" and 5 * rmax or 0)
    end
    o.disk = disk
  end
  o.evaluate = opts.evaluate or function(material, seed) return lab_evaluate(lab, o, material, seed) end
  local seeds = opts.seeds or 3
  if type(seeds) == "number" then
    if seeds < 1 or seeds ~= math.floor(seeds) then fail("seeds must be a count >= 1 or a list") end
    o.seeds = {}
    for i = 1, seeds do o.seeds[i] = i end
  elseif type(seeds) == "table" and #seeds > 0 then
    for i, seed in ipairs(seeds) do
      if type(seed) ~= "number" or seed ~= math.floor(seed) or math.abs(seed) >= 2 ^ 53 then
        fail("seeds[%d] must be a whole number, not %s", i, type(seed) == "number" and tostring(seed) or "a " .. type(seed))
      end
    end
    o.seeds = seeds
  else
    fail("seeds must be a count >= 1 or a list of seeds")
  end
  o.workers = opts.workers or seixo.cores()
  if type(o.workers) ~= "number" or o.workers < 1 then fail("workers must be >= 1") end
  o.maxeval = opts.maxeval or 40
  o.xtol = opts.xtol or 1e-3
  o.tolerance = opts.tolerance or 0.02
  o.guesses = opts.guesses or 3
  o.penalty = opts.penalty or 10
  -- numbers, checked here rather than compared deep in the search (a string
  -- for maxeval once failed there with Lua's own message)
  for _, k in ipairs({"maxeval", "guesses"}) do
    local v = o[k]
    if math.type(v) == nil or v ~= math.floor(v) or v < 0 or v == math.huge then
      fail("%s must be a whole number >= 0 (got %s)", k, tostring(v))
    end
  end
  for _, k in ipairs({"xtol", "tolerance", "penalty"}) do
    local v = o[k]
    if type(v) ~= "number" or not (v >= 0) or v == math.huge then
      fail("%s must be a finite number >= 0 (got %s)", k, tostring(v))
    end
  end
  o.algorithm = opts.algorithm or "bobyqa"
  for _, k in ipairs({"out", "log"}) do
    if opts[k] ~= nil and type(opts[k]) ~= "string" then
      fail("%s must be a path (a string; got %s)", k, type(opts[k]))
    end
  end
  local folder = opts.out and require("seixo.check").prefix_error(opts.out, "calibration")
  if folder then fail("%s", folder) end
  o.out = opts.out or "calibration"
  o.log = opts.log or (o.out .. ".csv")
  o.plot = opts.plot
  if opts.print ~= nil and opts.print ~= false and type(opts.print) ~= "function" then
    fail("print must be a function or false (got %s)", type(opts.print))
  end
  o.print = opts.print == false and function() end or opts.print or print
  o.settings = settings_of(o, opts.evaluate == nil)
  return o
end

-- -------------------------------------------------------------- search

local search -- below: the search of a calibration, on rank 0

local function calibrate(lab, opts)
  local o = check_options(lab, opts)
  -- over MPI ranks every rank runs specimens of its own, not one model
  -- decomposed: the models made from here on are each rank's (seixo.decompose)
  if seixo.ranks() > 1 then seixo.decompose(false) end
  if seixo.rank() > 0 then return serve_rank(o) end
  if seixo.ranks() == 1 then return search(lab, o) end
  -- an error of the search reaches the other ranks, which raise it alike
  -- (none waits for ever)
  local ok, result = pcall(search, lab, o)
  if not ok then
    pool.tell_ranks({failed = tostring(result)})
    error(result, 0)
  end
  return result
end

-- Rank 0's part (the whole of it on one rank): the search.
function search(lab, o)
  -- a worker process started for one run of this calibration
  local taken = pool.take(os.getenv("SEIXO_CALIBRATE_JOB"))
  local job = taken and taken.job
  if job and job.log == o.log then
    pool.answer(taken, run_job(o, job.x, job.seed))
    os.exit(0, true)
  end
  -- (a worker for a later calibration of the script replays this one from its log)
  local replay = job ~= nil
  -- the files written, checked before hours of runs, not after them (on
  -- rank 0 alone, which writes them: another rank may come here before
  -- rank 0 made their folder)
  for _, path in ipairs(replay and {} or {o.log, settings_path(o), o.out .. "_convergence.csv"}) do
    local ok, why = pool.writable(path)
    if not ok then fail("cannot write %s: %s", path, why) end
  end
  local mode = seixo.ranks() > 1 and "ranks" or (o.workers > 1 and script_command() and "processes" or "serial")
  if mode == "serial" then o.workers = 1 end

  local cache, log_rows = read_log(o)
  if not cache then
    cache, log_rows = {}, {}
    if not replay then write_settings(o) end
  end
  local history, best, worst_measured = {}, nil, 0
  local t_start = seixo.clock()

  -- Evaluates the candidates (arrays of quantized values): their runs not
  -- in the log go out in one batch; returns their summaries.
  local function evaluate(cands)
    local jobs = {}
    for ci, x in ipairs(cands) do
      for _, seed in ipairs(o.seeds) do
        if not cache[key_of(x, seed)] then jobs[#jobs + 1] = {x = x, seed = seed, candidate = #history + ci} end
      end
    end
    local t0 = seixo.clock()
    if #jobs > 0 and replay then
      fail("this worker replays the calibration logged in %s, which is not finished", o.log)
    end
    -- the log lists a batch's runs in their order (candidate, seed) whatever
    -- order they end in, the same order on every run
    local base, rows = #log_rows, {}
    local function record(i, rec)
      local j = jobs[i]
      cache[key_of(j.x, j.seed)] = rec
      local row = {j.candidate, j.seed, rec.status, rec.time}
      for _, v in ipairs(j.x) do row[#row + 1] = v end
      local at = #row -- (by index: a target not measured leaves its column empty, not the next one's)
      for m, k in ipairs(macros) do row[at + m] = rec.values and rec.values[k] or nil end
      rows[i] = row
      for k = #log_rows, base + 1, -1 do log_rows[k] = nil end
      for k = 1, #jobs do if rows[k] then log_rows[#log_rows + 1] = rows[k] end end
      lab.write_csv(o.log, log_header(o), log_rows)
      if rec.status ~= 1 then o.print(string.format("calibrate: run failed (seed %s): %s", tostring(j.seed), rec.error)) end
    end
    if mode == "ranks" then
      run_ranks(o, jobs, record)
    elseif mode == "processes" then
      run_processes(o, jobs, record)
    else
      for i, j in ipairs(jobs) do record(i, run_job(o, j.x, j.seed)) end
    end
    local out = {}
    for _, x in ipairs(cands) do
      local recs = {}
      for _, seed in ipairs(o.seeds) do recs[#recs + 1] = cache[key_of(x, seed)] end
      local c = summarize(o, x, recs)
      -- a candidate none of whose runs succeeded costs more than any measured
      -- one so far: at the fixed penalty alone, a failed candidate near a
      -- start far from the targets scored best, became the start of the
      -- guesses and of the search, and was returned as the result
      if not c.ok then c.objective = math.max(o.penalty, 2 * worst_measured) end
      if c.ok then worst_measured = math.max(worst_measured, c.objective) end
      history[#history + 1] = c
      c.index = #history
      if not best or (c.ok and not best.ok)
         or (c.ok == best.ok and ((c.within and not best.within)
                                  or (c.within == best.within and c.objective < best.objective))) then
        best = c
      end
      progress(o, c, #jobs == 0, seixo.clock() - t0)
      out[#out + 1] = c
    end
    if not replay then write_convergence(o, history) end
    return out
  end

  local function clamp(i, v) return quantize(math.min(o.upper[i], math.max(o.lower[i], v))) end

  -- 1. the pilot, with a perturbed candidate for each scaling whose exponent is unknown
  local roles, claimed = {}, {}
  for i, g in ipairs(o.groups) do
    for _, k in ipairs(g.role) do
      if o.targets[k] and not claimed[k] then
        roles[i], claimed[k] = k, true
        break
      end
    end
  end
  local cands, perturbed = {o.x0}, {}
  for i in pairs(roles) do
    if not o.groups[i].exponent then
      local x = copy(o.x0)
      local up = o.x0[i] * 2 <= o.upper[i]
      x[i] = clamp(i, up and o.x0[i] * 2 or o.x0[i] / 2)
      if x[i] ~= o.x0[i] then cands[#cands + 1], perturbed[i] = x, #cands + 1 end
    end
  end
  local first = evaluate(cands)
  local pilot = first[1]
  local exponents = {}
  for i, k in pairs(roles) do
    if o.groups[i].exponent then
      exponents[i] = o.groups[i].exponent
    elseif perturbed[i] then
      local p, q = pilot.achieved[k], first[perturbed[i]].achieved[k]
      if p and q and p.mean > 0 and q.mean > 0 then
        local e = math.log(q.mean / p.mean) / math.log(cands[perturbed[i]][i] / o.x0[i])
        if math.abs(e) > 0.05 then exponents[i] = e end
      end
    end
  end

  -- 2. scaling: each parameter with a role times (target / achieved)^(1/exponent),
  -- by a factor of 2 at most (a trust region: a measured exponent can be far
  -- off); an exponent that was measured is measured again between each guess
  -- and the candidate it came from (a secant in log-log space)
  local start = best
  for _ = 1, o.guesses do
    if start.within or not start.ok or #history >= o.maxeval then break end
    local x, moved = copy(start.x), false
    for i, k in pairs(roles) do
      local a = start.achieved[k]
      if exponents[i] and a and a.mean > 0 and o.targets[k] > 0 and k ~= "curve" then
        local f = math.min(2, math.max(0.5, (o.targets[k] / a.mean) ^ (1 / exponents[i])))
        x[i] = clamp(i, start.x[i] * f)
        moved = moved or x[i] ~= start.x[i]
      end
    end
    if not moved then break end
    local c = evaluate({x})[1]
    for i, k in pairs(roles) do
      local a, b = start.achieved[k], c.achieved[k]
      if not o.groups[i].exponent and a and b and a.mean > 0 and b.mean > 0
         and math.abs(math.log(c.x[i] / start.x[i])) > 0.05 then
        local e = math.log(b.mean / a.mean) / math.log(c.x[i] / start.x[i])
        if math.abs(e) > 0.05 then exponents[i] = e end
      end
    end
    if not c.ok or c.objective >= start.objective then break end
    start = c
  end

  -- 3. NLopt from the best so far, in parameters scaled to [0, 1] (log-scaled when positive)
  local function to_unit(i, v)
    if o.lower[i] > 0 then return math.log(v / o.lower[i]) / math.log(o.upper[i] / o.lower[i]) end
    return (v - o.lower[i]) / (o.upper[i] - o.lower[i])
  end
  local function from_unit(i, u)
    if o.lower[i] > 0 then return o.lower[i] * (o.upper[i] / o.lower[i]) ^ u end
    return o.lower[i] + u * (o.upper[i] - o.lower[i])
  end
  local left = o.maxeval - #history
  local status = "maxeval"
  if left > 0 and not best.within then
    local u0, lo, hi, step = {}, {}, {}, {}
    for i in ipairs(o.names) do u0[i], lo[i], hi[i], step[i] = to_unit(i, best.x[i]), 0, 1, 0.05 end
    -- a candidate with every target within the tolerance ends the search:
    -- its value as an error, which seixo.optimize raises unchanged
    local done = {}
    local ok, err, _, info = pcall(seixo.optimize, function(u)
      local x = {}
      for i in ipairs(o.names) do x[i] = clamp(i, from_unit(i, u[i])) end
      local c = evaluate({x})[1]
      if c.within then error(done) end
      return c.objective
    end, {x0 = u0, lower = lo, upper = hi, algorithm = o.algorithm, maxeval = left, xtol = o.xtol, step = step})
    if not ok and err ~= done then error(err, 0) end
    if ok then status = info.status end
  end
  if best.within then status = "tolerance" end

  local result = {parameters = {}, material = o.material_of(best.x), achieved = best.achieved,
                  objective = best.objective, evaluations = #history, status = status, log = o.log,
                  wall_time = seixo.clock() - t_start, history = {}}
  for i, n in ipairs(o.names) do result.parameters[n] = best.x[i] end
  for i, c in ipairs(history) do
    local p = {}
    for k, n in ipairs(o.names) do p[n] = c.x[k] end
    result.history[i] = {parameters = p, objective = c.objective, achieved = c.achieved}
  end
  result.table = final_table(o, best)
  if not replay then
    o.print(string.format("calibrate: %s after %d evaluations (%.1f s); best:\n%s", status, #history,
                          result.wall_time, result.table))
  end
  pool.tell_ranks({done = result})
  return result
end

--- Installs lab.calibrate in the lab's table.
function M.install(lab)
  -- the ranks' own models (seixo.decompose(false)) for the calibration's
  -- runs only: the script's models after it are decomposed again, and its
  -- files rank 0's again (each rank wrote the same files after it)
  lab.calibrate = function(opts)
    local shared = seixo.decompose()
    local _ <close> = setmetatable({}, {__close = function() seixo.decompose(shared) end})
    return calibrate(lab, opts)
  end
end

return M
