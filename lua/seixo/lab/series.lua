-- seixo.lab.series: a triaxial series (lab.series): a UCS and triaxial
-- tests of one specimen, run in turn, in processes (seixo.pool) or over
-- the MPI ranks, the Mohr-Coulomb fit of their peaks, an optional
-- quasi-static check at half the rate, and the series' figures.
local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local pool = require "seixo.pool"
local check = require "seixo.check"
local tables = require "seixo.lab.tables"
local frame = require "seixo.lab.frame"
local compression = require "seixo.lab.compression"
local mohr_coulomb = require "seixo.lab.mohr_coulomb"
local plots = require "seixo.lab.plots"
local series = {}

local c = check.module("lab")
local fail, check_keys, say, stress, number = c.fail, c.keys, c.say, c.stress, c.number
local copy = tables.copy
local check_spec, open_test, default_rate = frame.check_spec, frame.open, frame.default_rate
local polling = require("seixo.lab.polling").run
local compression_fields, test_keys, test_options, rate_control = compression.fields, compression.keys,
                                                                  compression.options, compression.rate_control

-- The tests of a series in processes (seixo.pool), `jobs` at a time: each
-- loads the specimen's file as it would here, so its results are the same
-- bit for bit. The longest first (the half-rate test, then the highest
-- confinement down: the greater the confinement, the more steps), so that
-- the last to start is the shortest and both cores end together. Each
-- test's log is passed on in the series' order (in_series_order).
local function longest_first(tests)
  local order = {}
  for i = 1, #tests do order[i] = i end
  table.sort(order, function(a, b)
    local ta, tb = tests[a], tests[b]
    if ta.slow ~= tb.slow then return ta.slow == true end
    if ta.opts.confining ~= tb.opts.confining then return ta.opts.confining > tb.opts.confining end
    return a < b
  end)
  return order
end

-- The tests' log lines in the series' order, whatever order the tests end
-- in (the longest start first, and the ends race): each test's lines go to
-- say_lines once every test before it has said its own, so a run says the
-- same lines in the same order every time, in processes and over the
-- ranks alike (they came in the order the tests ended). flush() says what
-- is left, in order, past the tests that never ended (a failure).
local function in_series_order(n, say_lines)
  local pending, first = {}, 1
  local o = {}
  function o.add(i, lines)
    pending[i] = lines
    while pending[first] do
      local ready = pending[first]
      pending[first], first = nil, first + 1
      say_lines(ready)
    end
  end
  function o.flush()
    for i = first, n do
      if pending[i] then say_lines(pending[i]) end
      pending[i] = nil
    end
    first = n + 1
  end
  return o
end

local function run_tests(spec, tests, jobs, opts)
  local order = longest_first(tests)
  local calls, results = {}, {}
  local said = in_series_order(#tests, function(lines) for _, line in ipairs(lines) do say(opts, "%s", line) end end)
  for k, i in ipairs(order) do
    local o = copy(tests[i].opts)
    -- a log function stays here: the worker prints, and its lines are passed on
    if opts.log == false then o.log = false else o.log = nil end
    calls[k] = {module = "seixo.lab", call = tests[i].call, args = {spec, o}}
  end
  local prefix = os.tmpname()
  local ok, err = pcall(pool.run, {jobs = calls, workers = jobs, prefix = prefix, command = pool.serve_command,
    done = function(k, answer, output, code)
      local t = tests[order[k]]
      local lines = {}
      for line in output:gmatch("[^\n]+") do lines[#lines + 1] = line end
      said.add(order[k], lines)
      if type(answer) ~= "table" or not answer.ok then said.flush() end
      if type(answer) ~= "table" then
        error(string.format("lab.series: the test at confining %g Pa ended without a result (exit code %s): %s",
                            t.opts.confining, tostring(code), (output:sub(-300):gsub("%s+$", ""))), 0)
      end
      if not answer.ok then error(answer.error, 0) end
      results[order[k]] = answer.value
    end})
  os.remove(prefix)
  if not ok then error(err, 0) end
  return results
end

-- The tests of a series over the MPI ranks (under mpirun, the models
-- shared): each test runs whole on one rank, on a model of that rank's own
-- (seixo.decompose(false) while they run), as the processes of run_tests
-- do: its results are the same bit for bit, and the tests take the ranks'
-- cores without a message a step. Rank 0 hands each idle rank a test (the
-- longest first; none after a failure, as the tests in turn stop at the
-- first), runs one itself while any is left (looking for idle ranks every
-- POLL_STEPS steps of its own test: polling; pool.hand_out), and says
-- each test's log lines in the series' order. Then every rank gets the results,
-- the lines rank 0 said (which the others say in turn: a log function of
-- the script's sees the same lines on every rank; one that raises stops
-- the lines there, on every rank) and the error to raise: that of the
-- first failing test in the series' order, else the log function's, else
-- rank 0's own. Rank 0 sends that outcome whatever happened, so no rank
-- waits for ever.
local function run_ranks(spec, tests, opts)
  local order = longest_first(tests)
  local function run(k)
    local t = tests[order[k]]
    local o, lines = copy(t.opts), {}
    if opts.log ~= false then o.log = function(line) lines[#lines + 1] = line end end
    local ok, value = pcall(compression[t.call], spec, o)
    return {k = k, ok = ok, value = ok and value or nil, error = not ok and tostring(value) or nil, lines = lines,
            rank = seixo.rank()}
  end
  local said, log_error = {}, nil
  local function say_all(lines)
    for _, line in ipairs(lines) do
      if log_error then return end
      said[#said + 1] = line
      local ok, e = pcall(say, opts, "%s", line)
      if not ok then log_error = tostring(e) end
    end
  end
  local shared = seixo.decompose()
  local _ <close> = setmetatable({}, {__close = function() seixo.decompose(shared) end})
  seixo.decompose(false)
  local done
  if seixo.rank() == 0 then
    local results, ran_on, errors = {}, {}, {}
    local in_order = in_series_order(#tests, say_all)
    local ok, own_error = pool.hand_out{
      more = function(k) return k <= #tests and next(errors) == nil and not log_error end,
      message = function(k) return {k = k} end,
      own = function(k, poll) return polling(poll, run, k) end,
      record = function(msg)
        local i = order[msg.k]
        ran_on[i] = msg.rank
        if msg.ok then results[i] = msg.value else errors[i] = msg.error end
        in_order.add(i, msg.lines)
      end}
    in_order.flush()
    local first
    for i = 1, #tests do if errors[i] then first = first or errors[i] end end
    done = {results = results, ran_on = ran_on, said = said,
            error = first or log_error or (not ok and tostring(own_error)) or nil}
    pool.tell_ranks({done = done})
  else
    done = pool.serve_rank(function(msg) return run(msg.k) end)
    say_all(done.said)
  end
  if done.error then error(done.error, 0) end
  return done.results, done.ran_on
end

-- The out of a series' test at confining s3: <out>_ucs, <out>_triaxial_5 (MPa).
local function series_out(out, s3)
  return s3 > 0 and string.format("%s_triaxial_%g", out, s3 / 1e6) or out .. "_ucs"
end

--- A triaxial series: the tests at each confining stress (0 is a UCS), then
--- the Mohr-Coulomb fit of their peaks, and the plots. opts as for
--- lab.triaxial, with confining = {sigma3, ...}; opts.out is a prefix.
--- quasi_static = true (tolerance 0.02) or a tolerance: the first test
--- again at half the strain rate. jobs: the tests run in that many
--- processes at once (default: the machine's cores; 1: one after another
--- in this process), with the same results bit for bit.
local series_keys = {"jobs", "quasi_static"}
for _, k in ipairs(test_keys) do series_keys[#series_keys + 1] = k end

function series.run(spec, opts)
  check_spec(spec, "series", compression_fields)
  opts = copy(opts or {})
  -- (and its log before the tests: with jobs > 1 the series says their lines itself)
  check_keys(opts, "series", series_keys)
  local list = opts.confining
  if type(list) ~= "table" or #list < 2 then error("lab.series: confining = {sigma3, ...} with two values or more", 2) end
  local distinct = false -- (the fit needs two: it ran every test, then found one; refused before any test)
  for i = 2, #list do distinct = distinct or list[i] ~= list[1] end
  if not distinct then fail("lab.series: confining has one stress (%s Pa): the fit needs two different ones", tostring(list[1])) end
  local jobs = number(opts.jobs or seixo.cores(), "jobs", "series", "a whole number of processes >= 1",
                      function(v) return v >= 1 and v < math.huge and v == math.floor(v) end)
  -- under mpirun, with the ranks sharing the models, the tests go to the
  -- ranks unless jobs = 1 asks for them in turn (each then decomposed);
  -- ranks on their own (seixo.decompose(false)) and a stock lua5.4, which
  -- has no seixo program to start, run the tests here, in turn
  local over_ranks = seixo.ranks() > 1 and seixo.decompose() and opts.jobs ~= 1
  if over_ranks then jobs = seixo.ranks() end
  if not over_ranks and (seixo.ranks() > 1 or (jobs > 1 and not pool.can_serve())) then jobs = 1 end
  local tolerance = opts.quasi_static == true and 0.02 or opts.quasi_static
  if tolerance and (type(tolerance) ~= "number" or not (tolerance > 0 and tolerance < 1)) then
    fail("lab.series: quasi_static must be true, false or a tolerance in (0, 1) (got %s)", check.got(opts.quasi_static))
  end
  opts.jobs, opts.quasi_static = nil, nil
  local out = opts.out
  if out ~= nil then c.prefix(out, "series") end -- (its tests' are its own with endings: out_ucs)
  local tests = {}
  for i, s3 in ipairs(list) do
    stress(s3, string.format("confining[%d]", i), "series")
    if spec.granular and s3 == 0 then -- (refused before any test starts)
      fail("lab.series: confining[%d] is 0: a granular specimen needs confining > 0 (nothing holds it together)", i)
    end
    local o = copy(opts)
    o.confining = s3
    o.out = out and series_out(out, s3)
    o.plot = false
    test_options(spec, o, "series") -- (as the test will, in the series' name and before any test)
    tests[i] = {call = s3 > 0 and "triaxial" or "ucs", opts = o}
  end
  -- the rate control's options against the strain rate the tests will
  -- take (the file's timestep), as they will check them
  local first = tests[1]
  local m = open_test(spec, first.opts, "series")
  local rate = first.opts.strain_rate or default_rate(m)
  m:close()
  local target, max_rate = rate_control(first.opts, rate, "series")
  if tolerance then
    -- the first test at half the rate: every speed of the loading-rate
    -- control halved, and the unbalanced-force ratio it allows too (the
    -- ratio grows with the speed)
    local o = copy(first.opts)
    o.strain_rate, o.max_rate, o.target_ratio = rate / 2, target and max_rate / 2 or nil, target and target / 2
    o.out = o.out and o.out .. "_half_rate"
    tests[#tests + 1] = {call = first.call, opts = o, slow = true}
  end
  jobs = math.min(jobs, #tests)
  local results, ran_on
  if over_ranks then
    results, ran_on = run_ranks(spec, tests, opts)
  elseif jobs > 1 then
    results = run_tests(spec, tests, jobs, opts)
  else
    results = {}
    for i, t in ipairs(tests) do results[i] = compression[t.call](spec, t.opts) end
  end
  local points = {}
  for i, s3 in ipairs(list) do points[i] = {sigma3 = s3, sigma1 = results[i].peak} end
  local fit = mohr_coulomb.fit(points)
  -- (a slope below 1 has no c and phi: its warning, not "c -nan MPa")
  local envelope = fit.warning and ": " .. fit.warning or string.format(" c %.4g MPa, phi %.2f deg", fit.c / 1e6, fit.phi)
  say(opts, "lab.series: Mohr-Coulomb%s (UCS of the fit %.4g MPa, R^2 %.4f, rms %.3g MPa)", envelope,
      fit.intercept / 1e6, fit.r2, fit.rms / 1e6)
  local s = {tests = {table.unpack(results, 1, #list)}, fit = fit, jobs = jobs, ran_on = ran_on}
  if tolerance then
    local slow, fast = results[#tests], results[1]
    local change = math.abs(slow.peak / fast.peak - 1)
    s.quasi_static = {test = slow, change = change, tolerance = tolerance, ok = change <= tolerance}
    say(opts, "lab.series: quasi-static check: peak %.4g MPa, %.4g MPa at half the rate: %.2f %% apart (tolerance "
        .. "%.3g %%)%s", fast.peak / 1e6, slow.peak / 1e6, 100 * change, 100 * tolerance,
        change <= tolerance and "" or ": too fast, lower the strain rate")
  end
  if out and opts.plot ~= false then
    local csvs = {}
    for i, r in ipairs(s.tests) do csvs[i] = series_out(out, r.confining) .. ".csv" end -- (the tests wrote them)
    plots.series(s, out, csvs)
  end
  return s
end

return series
