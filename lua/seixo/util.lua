-- seixo.util: pure-Lua helpers on top of the bindings.
--   local util = require "seixo.util"
-- Vectors are arrays of 2 or 3 numbers, as the bindings use them; every
-- function returns a new table and never changes its arguments.

local util = {}

-- A vector read from an object's field (b.pos) keeps its components in an
-- inner vector, read through metamethods: the checks read that plain copy.
local function plain(v)
  local mt = getmetatable(v)
  if type(mt) == "table" and rawget(mt, "__name") == "seixo.fieldvec" then return v:copy() end
  return v
end

-- The checks raise at `level` (default 3: the caller of the util function
-- that called them), so the message points at the user's script.
local function check_vec(v, name, fn, level)
  level = level or 3
  v = plain(v)
  if type(v) ~= "table" or rawlen(v) ~= 2 and rawlen(v) ~= 3 then
    error(string.format("bad argument '%s' to 'util.%s' (vector of 2 or 3 numbers expected, got %s)",
                        name, fn, type(v) == "table" and rawlen(v) .. " components" or type(v)), level)
  end
  for k = 1, rawlen(v) do
    if type(rawget(v, k)) ~= "number" then
      error(string.format("bad argument '%s' to 'util.%s' (component %d: number expected, got %s)",
                          name, fn, k, type(rawget(v, k))), level)
    end
  end
end

local function check_pair(a, b, fn)
  check_vec(a, "a", fn, 4)
  check_vec(b, "b", fn, 4)
  a, b = plain(a), plain(b)
  if rawlen(a) ~= rawlen(b) then
    error(string.format("bad arguments to 'util.%s' (vectors of %d and %d components)", fn, rawlen(a), rawlen(b)), 3)
  end
end

local function check_number(s, name, fn)
  if type(s) ~= "number" then
    error(string.format("bad argument '%s' to 'util.%s' (number expected, got %s)", name, fn, type(s)), 3)
  end
end

--- a + b
function util.add(a, b)
  check_pair(a, b, "add")
  local r = {}
  for k = 1, #a do r[k] = a[k] + b[k] end
  return r
end

--- a - b
function util.sub(a, b)
  check_pair(a, b, "sub")
  local r = {}
  for k = 1, #a do r[k] = a[k] - b[k] end
  return r
end

--- s a
function util.scale(a, s)
  check_vec(a, "a", "scale")
  check_number(s, "s", "scale")
  local r = {}
  for k = 1, #a do r[k] = a[k] * s end
  return r
end

--- a . b
function util.dot(a, b)
  check_pair(a, b, "dot")
  local s = 0
  for k = 1, #a do s = s + a[k] * b[k] end
  return s
end

--- a x b: a vector in 3D, the scalar z component in 2D
function util.cross(a, b)
  check_pair(a, b, "cross")
  if #a == 2 then return a[1] * b[2] - a[2] * b[1] end
  return {a[2] * b[3] - a[3] * b[2], a[3] * b[1] - a[1] * b[3], a[1] * b[2] - a[2] * b[1]}
end

--- |a|
function util.norm(a)
  check_vec(a, "a", "norm")
  local s = 0
  for k = 1, #a do s = s + a[k] * a[k] end
  return math.sqrt(s)
end

--- |a - b|
function util.dist(a, b)
  check_pair(a, b, "dist")
  local s = 0
  for k = 1, #a do s = s + (a[k] - b[k]) ^ 2 end
  return math.sqrt(s)
end

--- a / |a|; an error for the zero vector
function util.normalize(a)
  check_vec(a, "a", "normalize")
  local n = util.norm(a)
  if n == 0 then error("bad argument 'a' to 'util.normalize' (the zero vector has no direction)", 2) end
  local r = {}
  for k = 1, #a do r[k] = a[k] / n end
  return r
end

--- a + t (b - a)
function util.lerp(a, b, t)
  check_pair(a, b, "lerp")
  check_number(t, "t", "lerp")
  local r = {}
  for k = 1, #a do r[k] = a[k] + t * (b[k] - a[k]) end
  return r
end

--- The mean and the sample standard deviation of the numbers in xs (sd 0
--- for one number; nil, nil for none).
function util.mean_sd(xs)
  if type(xs) ~= "table" then error("bad argument 'xs' to 'util.mean_sd' (a list of numbers expected)", 2) end
  local n, s = #xs, 0
  if n == 0 then return nil, nil end
  for i = 1, n do
    if type(xs[i]) ~= "number" then
      error(string.format("bad argument 'xs' to 'util.mean_sd' (element %d is a %s, not a number)", i, type(xs[i])), 2)
    end
    s = s + xs[i]
  end
  local mean, ss = s / n, 0
  for _, x in ipairs(xs) do ss = ss + (x - mean) ^ 2 end
  return mean, n > 1 and math.sqrt(ss / (n - 1)) or 0
end

---------------------------------------------------------------- printing

-- (raw access throughout: printing never runs a table's metamethods)
local function is_array(t)
  local n = rawlen(t)
  local count = 0
  for _ in next, t do count = count + 1 end
  return count == n
end

local function key_text(k)
  if type(k) == "string" and k:match("^[%a_][%w_]*$") then return k end
  if type(k) == "string" then return string.format("[%q]", k) end
  return "[" .. tostring(k) .. "]"
end

local function sorted_keys(t)
  local keys = {}
  for k in next, t do keys[#keys + 1] = k end
  table.sort(keys, function(a, b)
    local ta, tb = type(a), type(b)
    if ta ~= tb then return ta < tb end
    if ta == "number" or ta == "string" then return a < b end
    return tostring(a) < tostring(b)
  end)
  return keys
end

local function show(v, depth, indent, seen, limit)
  if type(v) == "string" then return string.format("%q", v) end
  if type(v) ~= "table" then
    local ok, text = pcall(tostring, v)
    return ok and text or "<" .. type(v) .. " whose __tostring fails>"
  end
  local mt = getmetatable(v)
  if type(mt) == "table" and rawget(mt, "__tostring") then
    local ok, text = pcall(tostring, v)
    return ok and text or "<" .. type(v) .. " whose __tostring fails>"
  end
  if seen[v] then return "<cycle>" end
  if depth <= 0 then return "{...}" end
  seen[v] = true
  local parts = {}
  local count
  if is_array(v) then
    count = rawlen(v)
    for i = 1, math.min(count, limit) do parts[i] = show(rawget(v, i), depth - 1, indent + 1, seen, limit) end
  else
    local keys = sorted_keys(v)
    count = #keys
    for i = 1, math.min(count, limit) do
      local k = keys[i]
      parts[i] = key_text(k) .. " = " .. show(rawget(v, k), depth - 1, indent + 1, seen, limit)
    end
  end
  if count > limit then parts[#parts + 1] = "... (" .. count .. " entries)" end
  seen[v] = nil
  local flat = "{" .. table.concat(parts, ", ") .. "}"
  if #flat <= 78 or #parts == 0 then return flat end
  local pad = string.rep("  ", indent + 1)
  for i = 1, #parts do parts[i] = pad .. parts[i] end
  return "{\n" .. table.concat(parts, ",\n") .. "\n" .. string.rep("  ", indent) .. "}"
end

--- A readable text of any value: tables (keys sorted, cycles marked) to `depth` levels (default 4),
--- each cut after `limit` entries (default: none) with "... (n entries)".
function util.show(v, depth, limit)
  for name, x in pairs{depth = depth, limit = limit} do
    if math.type(x) ~= "integer" then
      error("bad argument '" .. name .. "' to 'util.show' (integer expected, got " .. type(x) .. ")", 2)
    end
  end
  return show(v, depth or 4, 0, {}, limit or math.maxinteger)
end

--- Prints each argument with util.show, separated by tabs.
function util.print(...)
  local out = {}
  for i = 1, select("#", ...) do out[i] = util.show((select(i, ...))) end
  print(table.concat(out, "\t"))
end

---------------------------------------------------------------- CSV

-- The records of a CSV text (RFC 4180): fields separated by commas, a
-- quoted field may hold commas, doubled quotes and line breaks.
local function csv_records(text)
  local records, fields, i, n = {}, {}, 1, #text
  local function finish_record()
    records[#records + 1] = fields
    fields = {}
  end
  while i <= n do
    local field
    if text:sub(i, i) == '"' then
      local parts, j = {}, i + 1
      while true do
        local q = text:find('"', j, true)
        if not q then error("util.read_csv: an unterminated quoted field", 3) end
        parts[#parts + 1] = text:sub(j, q - 1)
        if text:sub(q + 1, q + 1) == '"' then
          parts[#parts + 1] = '"'
          j = q + 2
        else
          i = q + 1
          break
        end
      end
      field = table.concat(parts)
    else
      local e = text:find("[,\r\n]", i) or n + 1
      field = text:sub(i, e - 1)
      i = e
    end
    fields[#fields + 1] = field
    local c = text:sub(i, i)
    if c == "," then
      i = i + 1
      if i > n then fields[#fields + 1] = "" end
    elseif c == "\r" or c == "\n" then
      i = i + ((c == "\r" and text:sub(i + 1, i + 1) == "\n") and 2 or 1)
      finish_record()
    elseif i <= n then
      error("util.read_csv: text after a closing quote", 3)
    end
  end
  if #fields > 0 then finish_record() end
  return records
end

--- Reads a CSV file written by m:history_csv: returns {header = {...}, columns = {name = {values}}, rows = n};
--- empty cells are nil, numbers are numbers; quoted names (with commas, quotes, line breaks) are read back.
-- A cell as a number when it is one: Lua's tonumber, and the spellings of
-- NaN and the infinities that seixo's writers and C's printf give.
local special = {nan = 0 / 0, ["-nan"] = 0 / 0, inf = math.huge, ["-inf"] = -math.huge}
local function value(cell)
  local x = tonumber(cell)
  if x then return x end
  x = special[cell:lower()]
  if x then return x end
  return cell
end

function util.read_csv(path)
  if type(path) ~= "string" then
    error("bad argument 'path' to 'util.read_csv' (string expected, got " .. type(path) .. ")", 2)
  end
  local f, err = io.open(path, "rb")
  if not f then error("util.read_csv: " .. err, 2) end
  local text = f:read("a")
  f:close()
  local records = csv_records(text)
  local header, columns = records[1] or {}, {}
  for _, name in ipairs(header) do columns[name] = {} end
  for row = 2, #records do
    local cells = records[row]
    for i, name in ipairs(header) do
      local cell = cells[i]
      if cell and cell ~= "" then columns[name][row - 1] = value(cell) end
    end
  end
  return {header = header, columns = columns, rows = math.max(#records - 1, 0)}
end

return util
