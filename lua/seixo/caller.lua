-- Errors at the caller's line: what fails inside one of the library's
-- exported functions is raised again from its caller's position, not
-- from inside seixo's Lua files (their helpers raise at a fixed level,
-- which is the caller's only for some call paths). An error raised in
-- another of seixo's modules counts as the library's.
-- A warning names the caller's line too (caller.where; the core's warnings
-- ask it when this module is loaded).
--   local caller = require "seixo.caller"
--   caller.wrap(module_table)   -- every function of the table
--   caller.where()              -- "file:line: " of the user's line
local caller = {}

-- The library's directory (this file's), and whether a module ("lab",
-- "lab/series") is one of its files: any file there is the library's, so a
-- new module needs no list kept by hand (package.searchpath looks with
-- C's fopen, never the ranks' shared io.open under mpirun).
local dir = debug.getinfo(1, "S").source:match("^@(.*[/\\])") or ""
local known = {}
local function own(module)
  if known[module] == nil then
    known[module] = dir ~= "" and package.searchpath(module, dir .. "?.lua", "", "") ~= nil
  end
  return known[module]
end

-- The message of an error raised in one of the library's files (its
-- position, "seixo/lab.lua:12: " or "seixo/lab/material.lua:34: ", taken
-- off), or nil.
local function own_message(e)
  for _, file in ipairs{"[%w_]+", "[%w_]+/[%w_]+"} do
    local module, inner = e:match("^[^\n]-seixo/(" .. file .. ")%.lua:%d+: (.*)$")
    if inner and own(module) then return inner end
  end
end

function caller.at_caller(f)
  return function(...)
    local r = table.pack(pcall(f, ...))
    if r[1] then return table.unpack(r, 2, r.n) end
    local e = r[2]
    if type(e) ~= "string" then error(e, 0) end
    local info = debug.getinfo(2, "Sl")
    local here = info and info.currentline > 0 and (info.short_src .. ":" .. info.currentline .. ": ")
    if here and e:sub(1, #here) == here then error(e, 0) end -- already the caller's
    local inner = own_message(e)
    if inner then error(inner, 2) end
    if e:match("^[^\n:]+:%d+: ") then error(e, 0) end -- another file's (a user's callback)
    error(e, 2) -- no position (a helper's level fell on a tail call)
  end
end

-- The library's own files: beside this one and in lab/.
local function library(source)
  local module = source:sub(1, #dir + 1) == "@" .. dir and source:sub(#dir + 2):match("^([%w_/]+)%.lua$")
  return module and own(module)
end

-- "file:line: " of the innermost function on the stack that is neither
-- C nor one of the library's, the user's line a warning names (a value
-- given to seixo.lab and passed on to the core was named at the lab's
-- line that passed it); nil when there is none (a worker process running
-- a library call).
function caller.where()
  local level = 2
  while true do
    local info = debug.getinfo(level, "Sl")
    if not info then return nil end
    if info.what ~= "C" and info.currentline > 0 and not library(info.source) then
      return info.short_src .. ":" .. info.currentline .. ": "
    end
    level = level + 1
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
