-- seixo.pool's batches over the MPI ranks (pool.hand_out, pool.serve_rank,
-- pool.tell_ranks: what lab.series and lab.calibrate hand out with; test
-- lua_mpi_hand_out through mpi_same.sh). Rank 0 hands jobs 1 to R - 1 to
-- ranks 1 to R - 1, runs job R itself and, inside it, polls until the
-- ranks have answered every other job: that
-- ends only if its polls hand out jobs to the ranks as they end (without
-- them each rank would run one job, and rank 0 would wait for ever: the
-- run fails after 60 s). A second batch's record raises at rank 1's answer
-- met inside rank 0's run: the error is kept, raised after the run (which
-- ends as it would), and every rank gets it. Prints what the serial run
-- prints (serially rank 0 runs every job).
local pool = require "seixo.pool"
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local R, me = seixo.ranks(), seixo.rank()

local function batch(n, record_fn, own_fn)
  if me > 0 then
    return pool.serve_rank(function(msg) return {i = msg.i, rank = me, square = msg.i * msg.i} end)
  end
  local ok, err = pool.hand_out{
    more = function(i) return i <= n end,
    message = function(i) return {i = i} end,
    own = function(i, poll)
      own_fn(i, poll)
      return {i = i, rank = 0, square = i * i}
    end,
    record = record_fn}
  local result = {ok = ok, error = err and tostring(err) or nil}
  pool.tell_ranks({done = result})
  return result
end

-- 1. Polls hand out: rank 0's job R lasts until the ranks have done the others.
local n = 12 -- at least R + 1 for every R the suite runs (up to 4)
local got, where = {}, {}
local r1 = batch(n, function(a)
  if got[a.i] then error("job " .. a.i .. " recorded twice") end
  got[a.i], where[a.i] = a.square, a.rank
end, function(i, poll)
  if i ~= R or R == 1 then return end
  local t0 = seixo.clock()
  local function answered()
    local k = 0
    for _ in pairs(got) do k = k + 1 end
    return k
  end
  while answered() < n - 1 do
    poll()
    if seixo.clock() - t0 > 60 then error("rank 0's polls handed out no job in 60 s: " .. answered() .. " answered") end
  end
end)
if not r1.ok then error(r1.error, 0) end
if me == 0 then
  local sum = 0
  for i = 1, n do
    if got[i] ~= i * i then error("job " .. i .. " not recorded") end
    sum = sum + got[i]
  end
  if R > 1 then
    for i = 1, n do
      if (where[i] == 0) ~= (i == R) then error(string.format("job %d ran on rank %d", i, where[i])) end
    end
  end
  print(string.format("batch 1: ok %s, %d jobs, sum of squares %d", tostring(r1.ok), n, sum))
end

-- 2. A record that raises at job 1's answer: rank 1's, met inside rank
-- 0's run of job R under mpirun (kept, raised after it); serially rank
-- 0's own, at once.
local own_ended, seen1 = false, false
local r2 = batch(R + 1, function(a)
  if a.i == 1 then
    seen1 = true
    error("record refuses job 1", 0)
  end
end, function(i, poll)
  if i == R and R > 1 then
    -- polls until rank 1's answer to job 1 has come (the record raised:
    -- kept, or it would end this run here)
    local t0 = seixo.clock()
    repeat
      poll()
      if seixo.clock() - t0 > 60 then error("rank 1 did not answer job 1 in 60 s") end
    until seen1
    own_ended = true
  end
end)
if me == 0 and R > 1 and not own_ended then error("the kept error cut rank 0's own run short") end
print(string.format("batch 2: ok %s, error %s", tostring(r2.ok), tostring(r2.error)))

-- then every rank is free for a model decomposed over the ranks
local m = dofile(here .. "mpi_bed.lua")(10)
print("a model after it:", m:step(), m:hash())
