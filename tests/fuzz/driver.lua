-- The fuzz driver: runs tests/fuzz/api.lua and tests/fuzz/files.lua in
-- batches of child processes, each under a time limit, from a scratch
-- folder, and turns whatever goes wrong into a failure with its
-- reproducer: a failed case (the child's report), a crash or a sanitizer
-- report (a child that dies: the case it was running, from its log), a
-- hang (a batch past its time limit: the case it was running), a leak
-- (LeakSanitizer's report at a child's exit: the batch).
--   FUZZ_SEIXO=seixo FUZZ_H5MUTATE=h5mutate FUZZ_DOCS=docs/lua-api.md
--   FUZZ_API=n FUZZ_FILES=n [FUZZ_SEED=s] [FUZZ_BATCH=n] [FUZZ_FILE_BATCH=n]
--   [FUZZ_TIMEOUT=s] [FUZZ_LIMIT=s] [FUZZ_JOBS=n] seixo tests/fuzz/driver.lua
-- scripts/fuzz sets these; the meson test 'fuzz' runs a bounded number.
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
if here:sub(1, 1) ~= "/" then here = assert(os.getenv("PWD"), "PWD") .. "/" .. here end -- the children run elsewhere
local seixo_exe = assert(os.getenv("FUZZ_SEIXO") or (arg and arg[-1]), "FUZZ_SEIXO: the seixo executable")
local mutator = os.getenv("FUZZ_H5MUTATE")
local docs = os.getenv("FUZZ_DOCS") or ""
local api_cases = tonumber(os.getenv("FUZZ_API")) or 200
local file_cases = tonumber(os.getenv("FUZZ_FILES")) or 50
local seed = tonumber(os.getenv("FUZZ_SEED")) or os.time()
local batch = tonumber(os.getenv("FUZZ_BATCH")) or 200
local file_batch = tonumber(os.getenv("FUZZ_FILE_BATCH")) or 100
local timeout = tonumber(os.getenv("FUZZ_TIMEOUT")) or 600 -- a batch's limit, s
local limit = tonumber(os.getenv("FUZZ_LIMIT")) or 60 -- a case's, s
local jobs = tonumber(os.getenv("FUZZ_JOBS")) or 1

local function quote(s) return "'" .. tostring(s):gsub("'", "'\\''") .. "'" end
local function read(path)
  local f = io.open(path)
  if not f then return "" end
  local s = f:read("a")
  f:close()
  return s
end

local root = os.tmpname()
os.remove(root)
assert(os.execute("mkdir -p " .. quote(root)))

-- A batch: its command, run in the background; its files.
local function start(script, first, count, id)
  local dir = root .. "/b" .. id
  local b = {script = script, first = first, count = count, dir = dir, log = dir .. "/log", out = dir .. "/out",
             status = dir .. "/status"}
  os.execute("mkdir -p " .. quote(dir))
  local env = string.format("FUZZ_SEED=%d FUZZ_FIRST=%d FUZZ_COUNT=%d FUZZ_LOG=%s FUZZ_LIMIT=%g FUZZ_DOCS=%s %s",
                            seed, first, count, quote(b.log), limit, quote(docs),
                            mutator and ("FUZZ_H5MUTATE=" .. quote(mutator)) or "")
  -- damaged files make HDF5 leak on its own, which the suppressions name
  -- by HDF5's frames: only the slow unwinder sees them (HDF5 has no frame pointers)
  if script == "files.lua" then
    env = env .. ' LSAN_OPTIONS="${LSAN_OPTIONS:-}:fast_unwind_on_malloc=0:malloc_context_size=16"'
              .. ' ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0:malloc_context_size=16"'
  end
  -- scripts/fuzz --lsan: LeakSanitizer preloaded into a build without the sanitizers
  if os.getenv("FUZZ_PRELOAD") then env = env .. " LD_PRELOAD=" .. quote(os.getenv("FUZZ_PRELOAD")) end
  -- the status file appears when the child is done: 124 for the time limit (timeout(1))
  local cmd = string.format("(cd %s && env %s timeout -s KILL %d %s %s > %s 2>&1; echo $? > %s) &", quote(dir), env,
                            timeout, quote(seixo_exe), quote(here .. script), quote(b.out), quote(b.status))
  os.execute(cmd)
  return b
end

local function done(b) return read(b.status) ~= "" end

-- The last case a child's log says it started, and its number.
local function last_case(b)
  local last, k
  for line in read(b.log):gmatch("[^\n]+") do
    local n = line:match("^%S*%s*case (%d+)")
    if n then last, k = line, tonumber(n) end
  end
  return last or "(no case started)", k
end

local failures, ran = 0, {api = 0, files = 0}
local function report(b)
  local status = tonumber(read(b.status)) or -1
  local out = read(b.out)
  local kind = b.script == "api.lua" and "api" or "files"
  for line in out:gmatch("[^\n]+") do
    if line:match("^FAIL") then io.stderr:write(line, "\n") end
  end
  local reported = out:match("(%d+) failed\n?$")
  if status == 0 then
    ran[kind] = ran[kind] + b.count
    return
  end
  failures = failures + 1
  local last, k = last_case(b)
  local how = (status == 137 or status == 124) and "hung (killed after " .. timeout .. " s)" or status == 1 and reported and reported ~= "0"
              and reported .. " case(s) failed" or "ended with status " .. status
  io.stderr:write(string.format("FAIL %s batch %d..%d: %s; the case it was running: %s\n", b.script, b.first,
                                b.first + b.count - 1, how, last))
  if not (status == 1 and reported and reported ~= "0") then
    -- a crash, a sanitizer or leak report: the end of the child's output
    io.stderr:write(out:sub(-3000), "\n")
    ran[kind] = ran[kind] + (k and k - b.first + 1 or 0) -- up to the case that did not end
    return
  end
  ran[kind] = ran[kind] + b.count
end

-- every batch, at most `jobs` at a time; the API and file batches in
-- proportion, so that a long run stopped early has done some of both
local queue, apis, files = {}, {}, {}
for first = 1, api_cases, batch do apis[#apis + 1] = {"api.lua", first, math.min(batch, api_cases - first + 1)} end
if mutator then
  for first = 1, file_cases, file_batch do
    files[#files + 1] = {"files.lua", first, math.min(file_batch, file_cases - first + 1)}
  end
end
local ia, jf = 1, 1
while ia <= #apis or jf <= #files do
  if jf > #files or (ia <= #apis and (ia - 1) * #files <= (jf - 1) * #apis) then
    queue[#queue + 1] = apis[ia]
    ia = ia + 1
  else
    queue[#queue + 1] = files[jf]
    jf = jf + 1
  end
end
local t0 = seixo.clock()
local running, next_id = {}, 1
while #queue > 0 or #running > 0 do
  while #running < jobs and #queue > 0 do
    local q = table.remove(queue, 1)
    running[#running + 1] = start(q[1], q[2], q[3], next_id)
    next_id = next_id + 1
  end
  os.execute("sleep 0.2")
  for i = #running, 1, -1 do
    if done(running[i]) then
      report(running[i])
      table.remove(running, i)
    end
  end
end
os.execute("rm -rf " .. quote(root))
print(string.format("fuzz (seed %d): %d API cases, %d file cases in %.0f s; %d batch(es) failed", seed, ran.api,
                    ran.files, seixo.clock() - t0, failures))
if failures > 0 then os.exit(1) end
