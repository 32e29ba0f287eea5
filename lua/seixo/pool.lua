-- seixo.pool: jobs run in separate processes, a few at a time, to spread
-- independent work over the machine's cores (lab.series's tests,
-- lab.calibrate's runs). A process, not a thread: every job owns its
-- models, and its results are bit for bit those it gives run in the
-- calling process (the same file in, the same steps; numbers pass between
-- processes exactly, in hexadecimal).
--
-- The parent writes each job to a file and starts a shell command that
-- runs a seixo process on it; the worker writes its answer to the file the
-- job names, atomically. The parent waits for whichever job ends first: each
-- command ends by writing its job's number and exit code to a FIFO that the
-- parent holds open for reading and writing (so it never sees its end), a
-- plain blocking read with no polling; the next job starts at once in the
-- freed slot, so jobs of unequal lengths keep every core busy.
--   pool.run{jobs = {...}, workers = n, prefix = path, command = function(job_file) ... end,
--            done = function(i, answer, output, code) ... end}
--   -- in the worker: local e = pool.take(job_file) ... pool.answer(e, value)
--   -- or, for a call of a module's function: seixo -e "require('seixo.pool').serve()"

local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local pool = {}

-- Tables of numbers, strings and booleans to text and back; numbers in
-- hexadecimal, exactly.
function pool.serialize(v)
  local t = type(v)
  if t == "number" then
    if v ~= v then return "(0/0)" end
    if v == math.huge then return "math.huge" end
    if v == -math.huge then return "(-math.huge)" end
    return math.type(v) == "integer" and string.format("%d", v) or string.format("%a", v)
  elseif t == "string" then
    return string.format("%q", v)
  elseif t == "boolean" then
    return tostring(v)
  elseif t == "table" then
    local parts = {}
    for k, x in pairs(v) do parts[#parts + 1] = "[" .. pool.serialize(k) .. "]=" .. pool.serialize(x) end
    table.sort(parts) -- the same text on every run and rank (pairs' order is not)
    return "{" .. table.concat(parts, ",") .. "}"
  end
  error("a " .. t .. " cannot pass between processes", 2)
end

function pool.deserialize(text)
  local chunk = load("return " .. text, "=message", "t", {math = math})
  return chunk and chunk() or nil
end

function pool.read_all(path)
  local f = io.open(path, "r")
  if not f then return nil end
  local text = f:read("a")
  f:close()
  return text
end

--- A word for the shell.
function pool.quote(s) return "'" .. tostring(s):gsub("'", "'\\''") .. "'" end

--- A part of a temporary file's name that processes writing one file at
--- once (under mpirun with seixo.decompose(false) every rank writes it;
--- the workers of a pool) do not share: the rank, and the address of a new
--- table, which differs between processes (each maps its heap at an
--- address of its own) and between live tables. Not math.random: a rank
--- that ran more tests of a series than another, or drew a plot alone,
--- would draw more, and the ranks must draw alike after it.
function pool.tag() return string.format("%d.%s", seixo.rank(), (tostring({}):gsub("^table: ", ""))) end

-- An io or os call's message about the temporary name tmp, as the cause
-- for path's: "No such file or directory", not the temporary name.
local function cause(message, tmp)
  message = tostring(message)
  if message:sub(1, #tmp + 2) == tmp .. ": " then return message:sub(#tmp + 3) end
  return message
end

--- Writes text to path through a temporary name in the same folder,
--- renamed when complete: an interrupted write never leaves a truncated
--- file.
function pool.write_file(path, text)
  if type(path) ~= "string" then error("cannot write a file: its path must be a string, not a " .. type(path), 2) end
  local ok_kind, what = seixo.replaceable(path)
  if not ok_kind then error("cannot write " .. path .. ": it " .. what, 2) end
  local tmp = path .. ".tmp" .. pool.tag()
  local f, opened = io.open(tmp, "w")
  if not f then error("cannot write " .. path .. ": " .. cause(opened, tmp), 2) end
  local ok, err = f:write(text)
  f:close()
  if not ok then os.remove(tmp); error("cannot write " .. path .. ": " .. cause(err, tmp), 2) end
  local done, why = os.rename(tmp, path)
  if not done then os.remove(tmp); error("cannot write " .. path .. ": " .. cause(why, tmp), 2) end
end

--- Whether a file can be made at path: true, or nil and the cause (a
--- probe through a temporary name beside it, removed at once). A genesis
--- or a test checks its output folders before its work, not when done.
function pool.writable(path)
  if path == "" or path:sub(-1) == "/" then return nil, "not a file's name" end
  local replaceable, what = seixo.replaceable(path)
  if not replaceable then return nil, "it " .. what end
  local there = io.open(path, "r") -- (a folder opens, and reads as one)
  if there then
    local _, _, code = there:read(0)
    there:close()
    if code == 21 then return nil, "Is a directory" end
  end
  local tmp = path .. ".tmp" .. pool.tag()
  local f, opened = io.open(tmp, "w")
  if not f then return nil, cause(opened, tmp) end
  f:close()
  os.remove(tmp)
  return true
end

-- The process id of a job's command, from its shell's file (written just
-- after the job starts: a job begun a moment ago is waited for, up to 5 s).
local function pid_of(stem)
  for _ = 1, 500 do
    local pid = (pool.read_all(stem .. ".pid") or ""):match("^(%d+)\n")
    if pid then return pid end
    os.execute("sleep 0.01")
  end
end

-- Interrupts the workers (seixo stops at a SIGINT as at Ctrl-C), once a
-- second until they have gone, for up to 30 s in all: a worker that has
-- only just started ignores the signal until seixo sets its handler (a
-- background command's SIGINT is ignored by the shell that starts it).
local function interrupt(pids)
  local function alive(list)
    local left = {}
    for _, pid in ipairs(list) do
      if os.execute("kill -0 " .. pid .. " 2>/dev/null") then left[#left + 1] = pid end
    end
    return left
  end
  for _ = 1, 30 do
    pids = alive(pids)
    if #pids == 0 then return end
    os.execute("kill -INT " .. table.concat(pids, " ") .. " 2>/dev/null")
    for _ = 1, 10 do
      if #alive(pids) == 0 then return end
      os.execute("sleep 0.1")
    end
  end
end

--- Runs o.jobs (serializable tables) in processes, o.workers at a time:
--- job i is written to <prefix>.job<i>.lua and o.command(that file) is a
--- shell command running the worker (its output goes to a file). As each
--- job ends, in the order they end, o.done(i, answer, output, code) gets
--- what the worker answered (nil if it died first), its output and its
--- exit code. The job files are removed. o.command must give a simple
--- command (variables, a program, its arguments): it runs in the
--- background so that its process id is known.
function pool.run(o)
  local q = pool.quote
  -- the FIFO in the temporary directory, where a FIFO can be made (the
  -- prefix may be on a file system that has none)
  local fifo = os.tmpname()
  os.remove(fifo)
  local made = os.execute("mkfifo " .. q(fifo))
  local events = (made == true or made == 0) and io.open(fifo, "r+")
  if not events then error("seixo.pool: cannot make the FIFO " .. fifo .. " (mkfifo)", 2) end
  local running, count, next_job = {}, 0, 1
  local function stem(i) return string.format("%s.job%d", o.prefix, i) end
  local function start(i)
    local s = stem(i)
    -- the script the workers' files name as their provenance (seixo.script)
    local sx = rawget(_G, "seixo") -- (nil in a stock Lua)
    pool.write_file(s .. ".lua", pool.serialize({job = o.jobs[i], answer = s .. ".out", script = sx and sx.script()}))
    local h, why = io.popen(string.format("{ %s > %s 2>&1 & echo $! > %s; wait $!; echo %d $? > %s; }",
                                          o.command(s .. ".lua"), q(s .. ".txt"), q(s .. ".pid"), i, q(fifo)))
    if not h then error("seixo.pool: cannot start a process: " .. tostring(why), 0) end
    running[i], count = h, count + 1
  end
  local ok, err = pcall(function()
    while next_job <= #o.jobs or count > 0 do
      while count < o.workers and next_job <= #o.jobs do
        start(next_job)
        next_job = next_job + 1
      end
      local line = events:read("l")
      -- (a SIGINT interrupts the read; one sent to the process group, as
      -- a terminal's Ctrl-C is, reaches the workers too, and one sent to
      -- this process alone is passed on to them below)
      if not line then error("seixo.pool: interrupted while waiting for the jobs", 0) end
      local i, code = line:match("^(%d+) (%d+)$")
      i, code = tonumber(i), tonumber(code)
      running[i]:close()
      running[i], count = nil, count - 1
      local s = stem(i)
      local answer = pool.deserialize(pool.read_all(s .. ".out") or "")
      local output = pool.read_all(s .. ".txt") or ""
      for _, ext in ipairs({".lua", ".out", ".txt", ".pid"}) do os.remove(s .. ext) end
      o.done(i, answer, output, code)
    end
  end)
  -- on an error (an interrupt, a done callback's) the jobs still running
  -- are interrupted, then waited for: their answers would be dropped, and
  -- a `kill -INT` of this process alone (a scheduler's) had let them run
  -- to their end
  local pids = {}
  for i in pairs(running) do pids[#pids + 1] = pid_of(stem(i)) end
  interrupt(pids)
  for i, h in pairs(running) do
    h:close()
    for _, ext in ipairs({".lua", ".out", ".txt", ".pid"}) do os.remove(stem(i) .. ext) end
  end
  events:close()
  os.remove(fifo)
  if not ok then error(err, 0) end
end

--- Under mpirun, rank 0's part of a batch of jobs run each whole on one
--- rank (lab.series's tests, lab.calibrate's runs; the other ranks serve
--- them: pool.serve_rank). Rank 0 hands each idle rank the next job, runs
--- one itself while any is left, and meanwhile, at each poll() its own
--- run calls (lab's polling: every few hundred steps), collects what the
--- ranks that ended answered and hands them the next. o:
---   more(i)      whether job i, the next, may start (the jobs left, no failure)
---   message(i)   job i's message to a rank (a table)
---   own(i, poll) runs job i here; returns its answer, as a rank sends it
---   record(answer) takes one job's answer, rank 0's or a rank's
--- An error of record's met at a poll (the script's print, a log that
--- raises) is kept and raised after rank 0's run: inside it, it would pass
--- for the run's failure. After any error the jobs still out are awaited,
--- unrecorded (a rank sending an answer above MPI's eager size waits until
--- it is taken), so that every rank waits for rank 0 again. Returns true,
--- or false and the error.
function pool.hand_out(o)
  local idle, out, next_job = {}, 0, 1
  for r = 1, seixo.ranks() - 1 do idle[#idle + 1] = r end
  -- a rank's answer, waiting for one or not: true if one came (counted in
  -- before it is recorded, which may raise)
  local function collect(wait)
    local text, from = seixo.receive(wait)
    if not text then return false end
    idle[#idle + 1], out = from, out - 1
    o.record(pool.deserialize(text))
    return true
  end
  local function hand_out()
    while out > 0 and collect(false) do end
    while #idle > 0 and o.more(next_job) do
      seixo.send(table.remove(idle, 1), pool.serialize(o.message(next_job)))
      next_job, out = next_job + 1, out + 1
    end
  end
  local kept
  local function poll()
    local ok, e = pcall(hand_out)
    if not ok then kept = kept or e end
  end
  local ok, err = pcall(function()
    while o.more(next_job) or out > 0 do
      hand_out()
      if o.more(next_job) then
        local i = next_job
        next_job = i + 1 -- before the run: a poll goes on from the next
        local answer = o.own(i, poll)
        if kept then error(kept, 0) end
        o.record(answer)
      elseif out > 0 then
        collect(true)
      end
    end
  end)
  while out > 0 do
    seixo.receive(true)
    out = out - 1
  end
  return ok, err
end

--- Rank 0's last word to every other rank after pool.hand_out: a table
--- whose done the ranks return, or whose failed they raise.
function pool.tell_ranks(msg)
  local text = pool.serialize(msg)
  for r = 1, seixo.ranks() - 1 do seixo.send(r, text) end
end

--- A rank other than 0 under pool.hand_out: answers each job rank 0 sends
--- with run(message) until rank 0 tells it the end (pool.tell_ranks):
--- returns done, or raises failed.
function pool.serve_rank(run)
  while true do
    local msg = pool.deserialize((seixo.receive(true)))
    if msg.failed then error(msg.failed, 0) end
    if msg.done ~= nil then return msg.done end
    seixo.send(0, pool.serialize(run(msg)))
  end
end

--- In a worker: the job in the file (nil if none), to pass to pool.answer.
function pool.take(path)
  local e = path and pool.deserialize(pool.read_all(path) or "")
  return type(e) == "table" and e or nil
end

--- In a worker: the answer to the job taken.
function pool.answer(e, value) pool.write_file(e.answer, pool.serialize(value)) end

--- A worker for a call: the job in $SEIXO_POOL_JOB is {module =, call =,
--- args = {...}}; answers {ok = true, value = require(module)[call](args...)}
--- or {ok = false, error = message}.
function pool.serve()
  local e = pool.take(os.getenv("SEIXO_POOL_JOB"))
  if not e then error("seixo.pool: no job in $SEIXO_POOL_JOB", 0) end
  if e.script then seixo.script(e.script) end
  local j = e.job
  local ok, value = pcall(function() return require(j.module)[j.call](table.unpack(j.args)) end)
  pool.answer(e, ok and {ok = true, value = value} or {ok = false, error = tostring(value)})
end

-- Whether the running program is seixo (its `-v` says so), which the
-- workers of pool.serve_command need: a stock lua5.4 that loaded the
-- module is not. Asked once.
local is_seixo
function pool.can_serve()
  if is_seixo == nil then
    local h = io.popen(pool.quote(seixo.executable()) .. " -v 2>/dev/null")
    is_seixo = h ~= nil and (h:read("a") or ""):match("^seixo ") ~= nil
    if h then h:close() end
  end
  return is_seixo
end

--- The shell command of a pool.serve worker for a job file.
function pool.serve_command(job_file)
  return string.format("SEIXO_POOL_JOB=%s %s --threads 1 -e %s", pool.quote(job_file), pool.quote(seixo.executable()),
                       pool.quote("require('seixo.pool').serve()"))
end

return pool
