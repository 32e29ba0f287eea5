-- seixo.lab.tables: deep copies of the lab's option and result tables, and
-- overrides merged into a copy (a material's, a specimen's options).

local function copy(t)
  if type(t) ~= "table" then return t end
  local r = {}
  for k, v in pairs(t) do r[k] = copy(v) end
  return r
end

local function merge(base, over)
  local r = copy(base)
  for k, v in pairs(over or {}) do
    if type(v) == "table" and type(r[k]) == "table" then r[k] = merge(r[k], v) else r[k] = copy(v) end
  end
  return r
end

return {copy = copy, merge = merge}
