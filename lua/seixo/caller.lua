-- Errors at the caller's line: what fails inside one of the library's
-- exported functions is raised again from its caller's position, not
-- from inside seixo's Lua files (their helpers raise at a fixed level,
-- which is the caller's only for some call paths). An error raised in
-- another of seixo's modules counts as the library's.
--   local caller = require "seixo.caller"
--   caller.wrap(module_table)   -- every function of the table
local caller = {}

local own = {lab = true, check = true, pool = true, calibrate = true, periodic = true, plot = true, util = true, genesis = true, caller = true,
             joints = true}

function caller.at_caller(f)
  return function(...)
    local r = table.pack(pcall(f, ...))
    if r[1] then return table.unpack(r, 2, r.n) end
    local e = r[2]
    if type(e) ~= "string" then error(e, 0) end
    local info = debug.getinfo(2, "Sl")
    local here = info and info.currentline > 0 and (info.short_src .. ":" .. info.currentline .. ": ")
    if here and e:sub(1, #here) == here then error(e, 0) end -- already the caller's
    local module, inner = e:match("^[^\n]-seixo/([%w_]+)%.lua:%d+: (.*)$")
    if inner and own[module] then error(inner, 2) end
    if e:match("^[^\n:]+:%d+: ") then error(e, 0) end -- another file's (a user's callback)
    error(e, 2) -- no position (a helper's level fell on a tail call)
  end
end

-- Every function of t wrapped (once).
local wrapped = setmetatable({}, {__mode = "k"})
function caller.wrap(t)
  if wrapped[t] then return t end
  for name, f in pairs(t) do
    if type(f) == "function" then t[name] = caller.at_caller(f) end
  end
  wrapped[t] = true
  return t
end

return caller
